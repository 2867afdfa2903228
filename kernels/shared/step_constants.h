/* step_constants.h: the implicit Euler constants of one step, in a small buffer the host
 * writes each step (a buffer, not a struct argument, so that host and device never disagree
 * on padding). Shared by the host (host/ensemble/device_step_constants.cpp), the OpenCL kernels and
 * the Vulkan shaders: one numbering. After the SF_STEP_CONSTANTS shared numbers come
 * SF_SIGMA_CONSTANT_COUNT numbers per sigma point s, at [SF_STEP_CONSTANTS + k S + s]
 * (SF_SIGMA_CONSTANT): what the candidate effects (host/model/effects.h) may set per sigma
 * point, from the model's values and the sigma point's effects. */
#ifndef SIGMAFEM_STEP_CONSTANTS_H
#define SIGMAFEM_STEP_CONSTANTS_H

#define SF_H 0                 /* time step h */
#define SF_CG_TOLERANCE2 1     /* squared relative CG tolerance */
#define SF_STEP_CONSTANTS 2    /* (the rotation method is the kernels' build option SF_POLAR_FRAMES) */

/* Per sigma point, k: */
#define SF_GRAVITY 0             /* 3 numbers: gravity (m/s^2) */
#define SF_SO_SHIFT 3            /* 3 numbers: the control target shift so(t_{n+1} - lag) - so(0) */
#define SF_INVERSE_D0_SQUARED 6  /* 1/d0^2 of the ligament law k u (1 + |u|^2/d0^2); 0: linear */
#define SF_YOUNG_SCALE 7         /* multiplies the elastic forces and products (young_scale) */
#define SF_MASS_FACTOR 8         /* 1 + h b, with Rayleigh damping B = a K + b M */
#define SF_STIFFNESS_FACTOR 9    /* h (h + a) */
#define SF_RAYLEIGH_MASS 10      /* b */
#define SF_VELOCITY_FACTOR 11    /* h + a */
#define SF_LAMBDA_SCALE 12       /* multiplies the elements' Lame lambda (lambda_scale; mu kept) */
#define SF_SIGMA_CONSTANT_COUNT 13
/* Then, from k = SF_REGION_SCALES, one per region slot: what multiplies both Lame terms of the
 * elements whose rest state names that slot (device_layout.h, SF_REST_REGION_SLOT): slot 0,
 * always 1, for the elements of no estimated region; slot 1 + r for estimated region r, its
 * sigma point's Young's modulus over the model's (issue 19). */
#define SF_REGION_SCALES SF_SIGMA_CONSTANT_COUNT

/* The most parameters a device ensemble estimates (the re-centring's arrays, recenter.h;
 * the host's kDeviceMaxParameters). */
#define SF_MAX_PARAMETERS 64

/* Constant k of sigma point s, with S sigma points, in the buffer c. */
#define SF_SIGMA_CONSTANT(c, k, s, S) (SF_LOAD(c, SF_STEP_CONSTANTS + (k) * (S) + (s)))

#endif /* SIGMAFEM_STEP_CONSTANTS_H */
