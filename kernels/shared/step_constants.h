/* step_constants.h: the implicit Euler constants of one step, in a small buffer the host
 * writes each step (a buffer, not a struct argument, so that host and device never disagree
 * on padding). Shared by the host (host/ensemble/ensemble_tables.cpp), the OpenCL kernels and
 * the Vulkan shaders: one numbering. */
#ifndef SIGMAFEM_STEP_CONSTANTS_H
#define SIGMAFEM_STEP_CONSTANTS_H

#define SF_H 0                 /* time step h */
#define SF_MASS_FACTOR 1       /* 1 + h b */
#define SF_STIFFNESS_FACTOR 2  /* h (h + a) */
#define SF_RAYLEIGH_MASS 3     /* b */
#define SF_VELOCITY_FACTOR 4   /* h + a */
#define SF_GRAVITY 5           /* 3 numbers */
#define SF_SO_SHIFT 8          /* 3 numbers: so(t_{n+1}) - so(0), the control target shift */
#define SF_CG_TOLERANCE2 11    /* squared relative CG tolerance */
#define SF_STEP_CONSTANTS 12

#endif /* SIGMAFEM_STEP_CONSTANTS_H */
