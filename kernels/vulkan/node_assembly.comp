/* node_assembly: per node and sigma point, the element outputs gathered at the node plus the
 * nodal terms of the implicit Euler system (as kernels/opencl/node_assembly.cl). Compiled
 * twice (cmake/compile_glsl.cmake):
 *   -DSF_ENTRY_NODE_RHS      node_rhs:     rhs = h (f - (h + a) K v - b M v) and the inverse
 *                                          Jacobi diagonal of A
 *   -DSF_ENTRY_NODE_PRODUCT  node_product: q = A d, in every CG iteration
 * One invocation per (node, sigma). */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "node_assembly.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;

#if defined(SF_ENTRY_NODE_RHS)
layout(std430, binding = SF_NODE_RHS_REST_POSITIONS) restrict readonly buffer RestPositions { real rest_positions[]; };
layout(std430, binding = SF_NODE_RHS_X) restrict readonly buffer X { real x[]; };
layout(std430, binding = SF_NODE_RHS_V) restrict readonly buffer V { real v[]; };
layout(std430, binding = SF_NODE_RHS_ELEMENT_OUT) restrict readonly buffer ElementOut { real element_out[]; };
layout(std430, binding = SF_NODE_RHS_ELEMENT_DIAGONAL) restrict readonly buffer ElementDiagonal { real element_diagonal[]; };
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
  real m = sf_solver_mass(mass[n], spring);
  SfNodeConstants at;
  SF_LOAD_NODE_CONSTANTS(c, s, S, at)
  real f_elements[3];
  real diagonal[3];
  SF_CORNER_SUMS(element_out, incidence_offsets, incidence, n, s, S, f_elements)
  SF_CORNER_SUMS(element_diagonal, incidence_offsets, incidence, n, s, S, diagonal)
  real u[3];
  for (uint k = 0u; k < 3u; ++k) u[k] = x[(3u * n + k) * S + s] - rest_positions[3u * n + k];
  real law = sf_ligament_law(spring, control_k[n], u, at.inverse_d0_squared);
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * S + s;
    rhs[row] = sf_node_rhs_row(at, int(k), f_elements[k], u[k], v[row], spring, control_k[n], law,
                               mass[n], m);
    inverse_diagonal[row] = sf_node_inverse_diagonal(at, diagonal[k], spring, m);
  }
}

#elif defined(SF_ENTRY_NODE_PRODUCT)
layout(std430, binding = SF_NODE_PRODUCT_D) restrict readonly buffer D { real d[]; };
layout(std430, binding = SF_NODE_PRODUCT_ELEMENT_OUT) restrict readonly buffer ElementOut { real element_out[]; };
layout(std430, binding = SF_NODE_PRODUCT_Q) restrict writeonly buffer Q { real q[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint s = gid % S;
  uint n = gid / S;
  real spring;
  SF_SPRING_OF(n, s, S, spring)
  real m = sf_solver_mass(mass[n], spring);
  real sum[3];
  SF_CORNER_SUMS(element_out, incidence_offsets, incidence, n, s, S, sum)
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * S + s;
    q[row] = SF_SYSTEM_ROW(c, s, S, sum[k], spring, m, d[row]);
  }
}

#else
#  error "node_assembly.comp: define SF_ENTRY_NODE_RHS or SF_ENTRY_NODE_PRODUCT"
#endif
