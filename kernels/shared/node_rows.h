/* node_rows.h: one node's rows of the implicit Euler system, for every device back end (the
 * node_rhs and node_product kernels of node_assembly.cl and .comp, and the CG kernels that
 * form A d themselves). Host: host/reference/implicit_euler.h.
 *   A = (1 + h b) M + h (h + a) K,   K = elastic tangent + springs on the diagonal.
 * Springs: a node's stiffness is the sum of its ligaments' per-node stiffness (which differs
 * between sigma points: ligament_k[l * S + s]) and its control stiffness (shared). The
 * factors of A, the damping, Young's modulus scale and the loads are per sigma point
 * (SF_SIGMA_CONSTANT, step_constants.h): the elements' K d is scaled where it is gathered.
 *
 * The functions take values; the two macros that read buffers take the buffers' names, which
 * are a kernel's arguments in OpenCL C and the shader's storage buffers in GLSL (GLSL cannot
 * pass a buffer to a function). Sums run in the incidence order: deterministic, no atomics. */
#ifndef SIGMAFEM_NODE_ROWS_H
#define SIGMAFEM_NODE_ROWS_H

#include "dialect.h"
#include "step_constants.h"

/* sum[k] = sum over node n's incident corners of a per-corner element output, axis k, sigma
 * s, for the three axes in one pass (each corner index is loaded once, not once per axis:
 * on lavapipe every load of a lane-varying address is a scalar gather). */
#define SF_CORNER_SUMS(values_, incidence_offsets_, incidence_, n, s, S, sum) \
  {                                                                            \
    sum[0] = SF_LIT(0);                                                        \
    sum[1] = SF_LIT(0);                                                        \
    sum[2] = SF_LIT(0);                                                        \
    int end_ = SF_LOAD(incidence_offsets_, (n) + 1);                           \
    for (int i_ = SF_LOAD(incidence_offsets_, n); i_ < end_; ++i_) {           \
      SF_INDEX_TYPE base_ = SF_INDEX(3 * SF_LOAD(incidence_, i_)) * (S) + (s); \
      sum[0] += SF_LOAD(values_, base_);                                       \
      sum[1] += SF_LOAD(values_, base_ + (S));                                 \
      sum[2] += SF_LOAD(values_, base_ + 2 * (S));                             \
    }                                                                          \
  }

/* spring = the spring stiffness on node n for sigma point s: its control spring and its
 * ligaments', in the ligaments' order. */
#define SF_NODE_SPRING(ligament_offsets_, ligament_of_node_, ligament_k_, control_k_, n, s, S, \
                       spring)                                                                 \
  {                                                                                            \
    spring = SF_LOAD(control_k_, n);                                                           \
    int end_ = SF_LOAD(ligament_offsets_, (n) + 1);                                            \
    for (int i_ = SF_LOAD(ligament_offsets_, n); i_ < end_; ++i_)                              \
      spring += SF_LOAD(ligament_k_, SF_INDEX(SF_LOAD(ligament_of_node_, i_)) * (S) + (s));    \
  }

/* What a sigma point's step constants give its node rows. */
struct SfNodeConstants {
  SF_REAL h;                  /* the time step */
  SF_REAL mass_factor;        /* 1 + h b */
  SF_REAL stiffness_factor;   /* h (h + a) */
  SF_REAL rayleigh_mass;      /* b */
  SF_REAL velocity_factor;    /* h + a */
  SF_REAL young_scale;
  SF_REAL inverse_d0_squared; /* the ligament law's 1/d0^2; 0: linear */
  SF_REAL gravity[3];
  SF_REAL so_shift[3];        /* the control target's shift from its start */
};

/* Loads sigma point s's node constants from the step constants buffer c_, each per-sigma
 * one by SIGMA(c_, k, s, S): SF_SIGMA_CONSTANT, or in Vulkan's sigma-quad shaders
 * SF_QUAD_CONSTANT, four sigma points' (kernels/vulkan/sigma_quads.h). */
#define SF_LOAD_NODE_CONSTANTS_BY(SIGMA, c_, s, S, out)                        \
  {                                                                            \
    out.h = SF_LIT(SF_LOAD(c_, SF_H));                                         \
    out.mass_factor = SIGMA(c_, SF_MASS_FACTOR, s, S);                         \
    out.stiffness_factor = SIGMA(c_, SF_STIFFNESS_FACTOR, s, S);               \
    out.rayleigh_mass = SIGMA(c_, SF_RAYLEIGH_MASS, s, S);                     \
    out.velocity_factor = SIGMA(c_, SF_VELOCITY_FACTOR, s, S);                 \
    out.young_scale = SIGMA(c_, SF_YOUNG_SCALE, s, S);                         \
    out.inverse_d0_squared = SIGMA(c_, SF_INVERSE_D0_SQUARED, s, S);           \
    for (int k_ = 0; k_ < 3; ++k_) {                                           \
      out.gravity[k_] = SIGMA(c_, SF_GRAVITY + k_, s, S);                      \
      out.so_shift[k_] = SIGMA(c_, SF_SO_SHIFT + k_, s, S);                    \
    }                                                                          \
  }
#define SF_LOAD_NODE_CONSTANTS(c_, s, S, out) SF_LOAD_NODE_CONSTANTS_BY(SF_SIGMA_CONSTANT, c_, s, S, out)

/* A node that no tetrahedron uses and no spring holds has a unit placeholder mass, so that
 * its rows of A are not zero (as in ImplicitEulerSystem). */
SF_FN SF_REAL sf_solver_mass(SF_REAL mass, SF_REAL spring) {
  return SF_SELECT(SF_BOTH_ZERO(mass, spring), SF_LIT(1), mass);
}

/* Row of A d, from the gathered element products Kd_elements and the row's d. */
SF_FN SF_REAL sf_system_row(SF_REAL stiffness_factor, SF_REAL young_scale, SF_REAL mass_factor,
                            SF_REAL Kd_elements, SF_REAL spring, SF_REAL m, SF_REAL d_row) {
  return stiffness_factor * (young_scale * Kd_elements + spring * d_row) +
         mass_factor * m * d_row;
}

/* The same with sigma point s's factors read from the step constants buffer c_ (by SIGMA, as
 * SF_LOAD_NODE_CONSTANTS_BY). */
#define SF_SYSTEM_ROW_BY(SIGMA, c_, s, S, Kd_elements, spring, m, d_row)                      \
  sf_system_row(SIGMA(c_, SF_STIFFNESS_FACTOR, s, S), SIGMA(c_, SF_YOUNG_SCALE, s, S),          \
                SIGMA(c_, SF_MASS_FACTOR, s, S), Kd_elements, spring, m, d_row)
#define SF_SYSTEM_ROW(c_, s, S, Kd_elements, spring, m, d_row) \
  SF_SYSTEM_ROW_BY(SF_SIGMA_CONSTANT, c_, s, S, Kd_elements, spring, m, d_row)

/* The ligament law's explicit factor k |u|^2/d0^2 of node u (its linear part k u is in the
 * spring; the control spring keeps the linear law): 0 for the linear law. */
SF_FN SF_REAL sf_ligament_law(SF_REAL spring, SF_REAL control_k, SF_IN(u, 3),
                              SF_REAL inverse_d0_squared) {
  SF_REAL u2 = SF_LIT(0);
  for (int k = 0; k < 3; ++k) u2 += u[k] * u[k];
  return (spring - control_k) * u2 * inverse_d0_squared;
}

/* Row k of the right-hand side h (f - (h + a) K v - b M v): the elastic force and (h + a) K v
 * from the elements (f_elements); springs pull towards rest (the control spring towards rest
 * + so_shift); the springs' own (h + a) k v; gravity on the node's mass. u = x - rest. */
SF_FN SF_REAL sf_node_rhs_row(SF_STRUCT(SfNodeConstants) at, int k, SF_REAL f_elements, SF_REAL u,
                              SF_REAL v, SF_REAL spring, SF_REAL control_k, SF_REAL law,
                              SF_REAL mass, SF_REAL m) {
  SF_REAL f = at.young_scale * f_elements;
  f -= spring * u - control_k * at.so_shift[k];
  f -= law * u;
  f += mass * at.gravity[k];
  f -= at.velocity_factor * spring * v;
  return at.h * (f - at.rayleigh_mass * m * v);
}

/* The inverse Jacobi diagonal of a row, from the elements' diagonal gathered at the node. */
SF_FN SF_REAL sf_node_inverse_diagonal(SF_STRUCT(SfNodeConstants) at, SF_REAL diagonal_elements,
                                       SF_REAL spring, SF_REAL m) {
  SF_REAL diagonal = at.young_scale * diagonal_elements;
  return SF_LIT(1) / (at.mass_factor * m + at.stiffness_factor * (diagonal + spring));
}

#endif /* SIGMAFEM_NODE_ROWS_H */
