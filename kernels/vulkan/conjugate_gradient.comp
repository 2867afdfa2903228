/* conjugate_gradient: Jacobi-preconditioned CG for all sigma points at once, with per-sigma
 * scalars and a per-sigma convergence flag (as kernels/opencl/conjugate_gradient.cl; host:
 * host/reference/conjugate_gradient.h, the same stopping rule |r| <= tolerance |b|).
 * Compiled twice (cmake/compile_glsl.cmake):
 *   -DSF_ENTRY_CG_START      cg_start:     the warm start's residual and first direction
 *   -DSF_ENTRY_CG_ITERATION  cg_iteration: one iteration after the product q = A d
 *
 * One work-group per sigma point owns every row of that sigma point, so the dot products are
 * reduced inside the group by a fixed tree (the same bits every run) and the rest of a CG
 * iteration after the product is one dispatch. The group size is specialization constant 0
 * (a power of two, set by the host). A sigma point that is inactive (converged, hit the cap
 * or broke down) returns at once, so the host records many iterations in one command buffer
 * without changing anyone's result.
 *
 * Per-sigma scalars (arrays of S): bb = b.b, rr = r.r, rz = r.z, active (1 while iterating),
 * converged (1 converged, 0 hit the cap or broke down), iterations (products done). */
#version 450
#extension GL_GOOGLE_include_directive : require

#if defined(SF_ENTRY_CG_START)
#  include "node_assembly.h"
#else
#  include "ensemble_layout.h"
#endif

layout(local_size_x_id = 0) in;

shared real scratch[gl_WorkGroupSize.x];

/* Tree reduction of one value per invocation of the group, returned to every invocation. */
real sf_group_sum(real value) {
  uint lid = gl_LocalInvocationID.x;
  barrier(); /* the previous sum's result has been read by everyone */
  scratch[lid] = value;
  memoryBarrierShared();
  barrier();
  for (uint stride = gl_WorkGroupSize.x / 2u; stride > 0u; stride /= 2u) {
    if (lid < stride) scratch[lid] += scratch[lid + stride];
    memoryBarrierShared();
    barrier();
  }
  return scratch[0];
}

#if defined(SF_ENTRY_CG_START)
layout(std430, binding = 8) restrict readonly buffer ElementOut { real element_out[]; };
layout(std430, binding = 9) restrict readonly buffer B { real b[]; };
layout(std430, binding = 10) restrict readonly buffer InverseDiagonal { real inverse_diagonal[]; };
layout(std430, binding = 11) restrict readonly buffer X { real x[]; };
layout(std430, binding = 12) restrict writeonly buffer R { real r[]; };
layout(std430, binding = 13) restrict writeonly buffer Z { real z[]; };
layout(std430, binding = 14) restrict writeonly buffer D { real d[]; };
layout(std430, binding = 15) restrict writeonly buffer BB { real bb[]; };
layout(std430, binding = 16) restrict writeonly buffer RR { real rr[]; };
layout(std430, binding = 17) restrict writeonly buffer RZ { real rz[]; };
layout(std430, binding = 18) restrict writeonly buffer Active { uint active_flags[]; };
layout(std430, binding = 19) restrict writeonly buffer Converged { uint converged[]; };
layout(std430, binding = 20) restrict writeonly buffer Iterations { int iterations[]; };

/* With q = A x (x = the last step's dv, products in element_out), r = b - q, z = M^-1 r,
 * d = z; bb, rr, rz; and whether the warm start is already good enough (b = 0 counts as
 * converged: the state update then uses dv = 0, the exact solution). */
void main() {
  uint S = sf_push.S;
  uint s = gl_WorkGroupID.x;
  real sum_bb = real(0);
  real sum_rr = real(0);
  real sum_rz = real(0);
  for (uint n = gl_LocalInvocationID.x; n < sf_push.count; n += gl_WorkGroupSize.x) {
    real spring = sf_node_spring(n, s, S);
    real m = sf_solver_mass(mass[n], spring);
    real Kd[3];
    SF_CORNER_SUMS(element_out, n, s, S, Kd)
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
      real q = sf_system_row(Kd[k], spring, m, x[row], s, S);
      real bi = b[row];
      real ri = bi - q;
      real zi = inverse_diagonal[row] * ri;
      r[row] = ri;
      z[row] = zi;
      d[row] = zi;
      sum_bb += bi * bi;
      sum_rr += ri * ri;
      sum_rz += ri * zi;
    }
  }
  sum_bb = sf_group_sum(sum_bb);
  sum_rr = sf_group_sum(sum_rr);
  sum_rz = sf_group_sum(sum_rz);
  if (gl_LocalInvocationID.x == 0u) {
    // An overflowed load (|b|^2 not finite) would pass the stop test as inf <= inf: a
    // breakdown instead, neither converged nor iterating, as in the CPU reference.
    bool breakdown = isinf(sum_bb) || isnan(sum_bb) || isinf(sum_rr) || isnan(sum_rr);
    bool done = !breakdown && (sum_bb == real(0) || sum_rr <= c[SF_CG_TOLERANCE2] * sum_bb);
    bb[s] = sum_bb;
    rr[s] = sum_rr;
    rz[s] = sum_rz;
    active_flags[s] = done || breakdown ? 0u : 1u;
    converged[s] = done ? 1u : 0u;
    iterations[s] = 0;
  }
}

#elif defined(SF_ENTRY_CG_ITERATION)
layout(std430, binding = 0) restrict readonly buffer C { real c[]; };
layout(std430, binding = 1) restrict readonly buffer InverseDiagonal { real inverse_diagonal[]; };
layout(std430, binding = 2) restrict buffer X { real x[]; };
layout(std430, binding = 3) restrict buffer R { real r[]; };
layout(std430, binding = 4) restrict buffer Z { real z[]; };
layout(std430, binding = 5) restrict buffer D { real d[]; };
layout(std430, binding = 6) restrict readonly buffer Q { real q[]; };
layout(std430, binding = 7) restrict readonly buffer BB { real bb[]; };
layout(std430, binding = 8) restrict buffer RR { real rr[]; };
layout(std430, binding = 9) restrict buffer RZ { real rz[]; };
layout(std430, binding = 10) restrict buffer Active { uint active_flags[]; };
layout(std430, binding = 11) restrict buffer Converged { uint converged[]; };
layout(std430, binding = 12) restrict buffer Iterations { int iterations[]; };

/* alpha = rz / d.q, x += alpha d, r -= alpha q, z = M^-1 r, then the convergence test
 * (|r|^2 <= tol^2 |b|^2), the cap, breakdown (a residual that is not finite: the matrix is
 * not SPD or the input held a NaN), and d = z + beta d. */
void main() {
  uint S = sf_push.S;
  uint s = gl_WorkGroupID.x;
  if (active_flags[s] == 0u) return; /* the same for the whole group: no barrier is left waiting */
  int count = iterations[s] + 1;
  real rz_old = rz[s];
  real bb_s = bb[s];
  uint first = gl_LocalInvocationID.x;

  real sum_dq = real(0);
  for (uint n = first; n < sf_push.count; n += gl_WorkGroupSize.x)
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
      sum_dq += d[row] * q[row];
    }
  real alpha = rz_old / sf_group_sum(sum_dq);

  real sum_rr = real(0);
  real sum_rz = real(0);
  for (uint n = first; n < sf_push.count; n += gl_WorkGroupSize.x)
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
      x[row] += alpha * d[row];
      real ri = r[row] - alpha * q[row];
      real zi = inverse_diagonal[row] * ri;
      r[row] = ri;
      z[row] = zi;
      sum_rr += ri * ri;
      sum_rz += ri * zi;
    }
  sum_rr = sf_group_sum(sum_rr);
  sum_rz = sf_group_sum(sum_rz);

  bool done = sum_rr <= c[SF_CG_TOLERANCE2] * bb_s;
  bool stop = done || isnan(sum_rr) || isinf(sum_rr) || count >= sf_push.max_iterations;
  memoryBarrierBuffer();
  barrier(); /* everyone has read the old scalars before they change */
  if (first == 0u) {
    iterations[s] = count;
    rr[s] = sum_rr;
    rz[s] = sum_rz;
    if (done) converged[s] = 1u;
    if (stop) active_flags[s] = 0u;
  }
  if (stop) return;
  real beta = sum_rz / rz_old;
  for (uint n = first; n < sf_push.count; n += gl_WorkGroupSize.x)
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
      d[row] = z[row] + beta * d[row];
    }
}

#else
#  error "conjugate_gradient.comp: define SF_ENTRY_CG_START or SF_ENTRY_CG_ITERATION"
#endif
