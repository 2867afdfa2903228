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
layout(std430, binding = 8) restrict readonly buffer RestPositions { real rest_positions[]; };
layout(std430, binding = 9) restrict readonly buffer X { real x[]; };
layout(std430, binding = 10) restrict readonly buffer V { real v[]; };
layout(std430, binding = 11) restrict readonly buffer ElementRhsOut { real element_rhs_out[]; };
layout(std430, binding = 12) restrict readonly buffer ElementDiagonal { real element_diagonal[]; };
layout(std430, binding = 13) restrict writeonly buffer Rhs { real rhs[]; };
layout(std430, binding = 14) restrict writeonly buffer InverseDiagonal { real inverse_diagonal[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint s = gid % S;
  uint n = gid / S;
  real spring = sf_node_spring(n, s, S);
  real m = sf_solver_mass(mass[n], spring);
  real f_elements[3];
  real diagonal[3];
  SF_CORNER_SUMS(element_rhs_out, n, s, S, f_elements)
  SF_CORNER_SUMS(element_diagonal, n, s, S, diagonal)
  /* This sigma point's loads (step_constants.h): c[at + k S] is load k. */
  uint at = SF_STEP_CONSTANTS + s;
  /* The ligament law's explicit part, k u |u|^2/d0^2 (its linear part k u is in spring): 0
   * for the linear law. */
  real u2 = real(0);
  for (uint k = 0u; k < 3u; ++k) {
    real u = x[(3u * n + k) * S + s] - rest_positions[3u * n + k];
    u2 += u * u;
  }
  real law = (spring - control_k[n]) * u2 * c[at + SF_INVERSE_D0_SQUARED * S];
  real young = c[at + SF_YOUNG_SCALE * S];
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * S + s;
    real xr = x[row];
    real vr = v[row];
    /* elastic force and (h + a) K v from the elements; springs pull towards rest (control
     * springs towards rest + so_shift); the springs' own (h + a) k v term. */
    real f = young * f_elements[k];
    real u = xr - rest_positions[3u * n + k];
    f -= spring * u - control_k[n] * c[at + (SF_SO_SHIFT + k) * S];
    f -= law * u;
    f += mass[n] * c[at + (SF_GRAVITY + k) * S];
    f -= c[at + SF_VELOCITY_FACTOR * S] * spring * vr;
    rhs[row] = c[SF_H] * (f - c[at + SF_RAYLEIGH_MASS * S] * m * vr);
    inverse_diagonal[row] = real(1) / (c[at + SF_MASS_FACTOR * S] * m +
                                       c[at + SF_STIFFNESS_FACTOR * S] * (young * diagonal[k] + spring));
  }
}

#elif defined(SF_ENTRY_NODE_PRODUCT)
layout(std430, binding = 8) restrict readonly buffer D { real d[]; };
layout(std430, binding = 9) restrict readonly buffer ElementOut { real element_out[]; };
layout(std430, binding = 10) restrict writeonly buffer Q { real q[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint s = gid % S;
  uint n = gid / S;
  real spring = sf_node_spring(n, s, S);
  real m = sf_solver_mass(mass[n], spring);
  real sum[3];
  SF_CORNER_SUMS(element_out, n, s, S, sum)
  for (uint k = 0u; k < 3u; ++k) {
    uint row = (3u * n + k) * S + s;
    q[row] = sf_system_row(sum[k], spring, m, d[row], s, S);
  }
}

#else
#  error "node_assembly.comp: define SF_ENTRY_NODE_RHS or SF_ENTRY_NODE_PRODUCT"
#endif
