/* node_assembly: per node and sigma point, the element outputs gathered at the node plus the
 * nodal terms of the implicit Euler system (as kernels/opencl/node_assembly.cl). Compiled
 * four times (cmake/compile_glsl.cmake):
 *   -DSF_ENTRY_NODE_RHS      node_rhs:     rhs = h (f - (h + a) K v - b M v) and the inverse
 *                                          Jacobi diagonal of A
 *   -DSF_ENTRY_NODE_PRODUCT  node_product: q = A d, in every CG iteration
 * One invocation per (node, sigma); or, with -DSF_ENTRY_NODE_RHS_QUADS and
 * -DSF_ENTRY_NODE_PRODUCT_QUADS (node_rhs_quads, node_product_quads: SF_SIGMA_QUADS, the CPU
 * form with S a multiple of 4), per node and four sigma points, read by rgba texels and
 * written as vec4s (sigma_quads.h; the same bits). node_rhs compiled with SF_FACTOR (*_factor:
 * CG preconditioned by factor_solve) leaves out the Jacobi diagonal, as OpenCL's does. */
#version 450
#extension GL_GOOGLE_include_directive : require
#if defined(SF_ENTRY_NODE_RHS_QUADS)
#  define SF_ENTRY_NODE_RHS
#  define SF_SIGMA_QUADS
#elif defined(SF_ENTRY_NODE_PRODUCT_QUADS)
#  define SF_ENTRY_NODE_PRODUCT
#  define SF_SIGMA_QUADS
#endif
#include "node_assembly.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;

#if defined(SF_ENTRY_NODE_RHS) && defined(SF_SIGMA_QUADS)
SF_READ_REALS(SF_NODE_RHS_REST_POSITIONS, rest_positions)
SF_READ_QUADS(SF_NODE_RHS_X, x)
SF_READ_QUADS(SF_NODE_RHS_V, v)
SF_READ_QUADS(SF_NODE_RHS_ELEMENT_OUT, element_out)
SF_READ_QUADS(SF_NODE_RHS_ELEMENT_DIAGONAL, element_diagonal)
SF_WRITE_QUADS(SF_NODE_RHS_RHS, rhs)
SF_WRITE_QUADS(SF_NODE_RHS_INVERSE_DIAGONAL, inverse_diagonal)

void main() {
  uint S = sf_push.S;
  uint Q = S / 4u;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * Q) return;
  uint q = gid % Q;
  uint n = gid / Q;
  SF_REAL spring;
  SF_SPRING_OF(n, q, Q, spring)
  SF_REAL mass_n = SF_REAL(SF_LOAD(mass, n));
  SF_REAL m = sf_solver_mass(mass_n, spring);
  SfNodeConstants at;
  SF_LOAD_NODE_CONSTANTS_BY(SF_QUAD_CONSTANT, c, q, S, at)
  SF_REAL f_elements[3];
  SF_CORNER_SUM_QUADS(element_out, incidence_offsets, incidence, n, q, Q, f_elements)
#if !defined(SF_FACTOR)
  SF_REAL diagonal[3];
  SF_CORNER_SUM_QUADS(element_diagonal, incidence_offsets, incidence, n, q, Q, diagonal)
#endif
  SF_REAL u[3];
  for (uint k = 0u; k < 3u; ++k) u[k] = SF_QUAD(x, (3u * n + k) * Q + q) - SF_REAL(SF_LOAD(rest_positions, 3u * n + k));
  SF_REAL control = SF_REAL(SF_LOAD(control_k, n));
  SF_REAL law = sf_ligament_law(spring, control, u, at.inverse_d0_squared);
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * Q + q;
    rhs[row] = sf_node_rhs_row(at, int(k), f_elements[k], u[k], SF_QUAD(v, row), spring, control, law, mass_n, m);
#if !defined(SF_FACTOR)
    inverse_diagonal[row] = sf_node_inverse_diagonal(at, diagonal[k], spring, m);
#endif
  }
}

#elif defined(SF_ENTRY_NODE_RHS)
SF_READ_REALS(SF_NODE_RHS_REST_POSITIONS, rest_positions)
SF_READ_REALS(SF_NODE_RHS_X, x)
SF_READ_REALS(SF_NODE_RHS_V, v)
SF_READ_REALS(SF_NODE_RHS_ELEMENT_OUT, element_out)
SF_READ_REALS(SF_NODE_RHS_ELEMENT_DIAGONAL, element_diagonal)
layout(std430, binding = SF_NODE_RHS_RHS) restrict writeonly buffer Rhs { real rhs[]; };
layout(std430, binding = SF_NODE_RHS_INVERSE_DIAGONAL) restrict writeonly buffer InverseDiagonal { real inverse_diagonal[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint s = gid % S;
  uint n = gid / S;
  real spring;
  SF_SPRING_OF(n, s, S, spring)
  real m = sf_solver_mass(SF_LOAD(mass, n), spring);
  SfNodeConstants at;
  SF_LOAD_NODE_CONSTANTS(c, s, S, at)
  real f_elements[3];
  SF_CORNER_SUMS(element_out, incidence_offsets, incidence, n, s, S, f_elements)
#if !defined(SF_FACTOR)
  real diagonal[3];
  SF_CORNER_SUMS(element_diagonal, incidence_offsets, incidence, n, s, S, diagonal)
#endif
  real u[3];
  for (uint k = 0u; k < 3u; ++k) u[k] = SF_LOAD(x, (3u * n + k) * S + s) - SF_LOAD(rest_positions, 3u * n + k);
  real control = SF_LOAD(control_k, n);
  real law = sf_ligament_law(spring, control, u, at.inverse_d0_squared);
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * S + s;
    rhs[row] = sf_node_rhs_row(at, int(k), f_elements[k], u[k], SF_LOAD(v, row), spring, control,
                               law, SF_LOAD(mass, n), m);
#if !defined(SF_FACTOR)
    inverse_diagonal[row] = sf_node_inverse_diagonal(at, diagonal[k], spring, m);
#endif
  }
}

#elif defined(SF_ENTRY_NODE_PRODUCT) && defined(SF_SIGMA_QUADS)
SF_READ_QUADS(SF_NODE_PRODUCT_D, d)
SF_READ_QUADS(SF_NODE_PRODUCT_ELEMENT_OUT, element_out)
SF_WRITE_QUADS(SF_NODE_PRODUCT_Q, q_out)

void main() {
  uint S = sf_push.S;
  uint Q = S / 4u;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * Q) return;
  uint q = gid % Q;
  uint n = gid / Q;
  SF_REAL spring;
  SF_SPRING_OF(n, q, Q, spring)
  SF_REAL m = sf_solver_mass(SF_REAL(SF_LOAD(mass, n)), spring);
  SF_REAL sum[3];
  SF_CORNER_SUM_QUADS(element_out, incidence_offsets, incidence, n, q, Q, sum)
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * Q + q;
    q_out[row] = SF_SYSTEM_ROW_BY(SF_QUAD_CONSTANT, c, q, S, sum[k], spring, m, SF_QUAD(d, row));
  }
}

#elif defined(SF_ENTRY_NODE_PRODUCT)
SF_READ_REALS(SF_NODE_PRODUCT_D, d)
SF_READ_REALS(SF_NODE_PRODUCT_ELEMENT_OUT, element_out)
layout(std430, binding = SF_NODE_PRODUCT_Q) restrict writeonly buffer Q { real q[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint s = gid % S;
  uint n = gid / S;
  real spring;
  SF_SPRING_OF(n, s, S, spring)
  real m = sf_solver_mass(SF_LOAD(mass, n), spring);
  real sum[3];
  SF_CORNER_SUMS(element_out, incidence_offsets, incidence, n, s, S, sum)
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * S + s;
    q[row] = SF_SYSTEM_ROW(c, s, S, sum[k], spring, m, SF_LOAD(d, row));
  }
}

#else
#  error "node_assembly.comp: define SF_ENTRY_NODE_RHS or SF_ENTRY_NODE_PRODUCT"
#endif
