/* conjugate_gradient: Jacobi-preconditioned CG for all sigma points at once, with per-sigma
 * scalars and a per-sigma convergence flag (host: host/reference/conjugate_gradient.h, the
 * same stopping rule |r| <= tolerance |b|).
 *
 * One work-group per sigma point owns every row of that sigma point, so the rest of a CG
 * iteration after the product q = A d is one kernel: d.q, the update with r.r and r.z, the
 * convergence test and the new direction, with the dot products reduced inside the group
 * (a fixed tree: the same bits every run) and no host round trip. Per iteration the host
 * enqueues three kernels (element_product, node_product, cg_iteration).
 *
 * A sigma point that has converged (or hit the iteration cap, or broke down) is inactive and
 * its group returns at once, so the host may enqueue several iterations between checks
 * without changing anyone's result.
 *
 * Per-sigma scalars (arrays of S): bb = b.b, rr = r.r, rz = r.z, active (1 while iterating),
 * converged (1 converged, 0 hit the cap or broke down), iterations (products done). */
#include "node_assembly.h"

/* Work-items per sigma point: a power of two (the host passes the same number). */
#ifndef SF_GROUP_SIZE
#  define SF_GROUP_SIZE 64
#endif

/* Tree reduction of one value per work-item of the group, returned to every work-item. */
static inline real sf_group_sum(__local real* scratch, real value) {
  uint lid = get_local_id(0);
  barrier(CLK_LOCAL_MEM_FENCE); /* the previous sum's result has been read by everyone */
  scratch[lid] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = SF_GROUP_SIZE / 2; stride > 0; stride /= 2) {
    if (lid < stride) scratch[lid] += scratch[lid + stride];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  return scratch[0];
}

/* The warm start's residual and the first direction: with q = A x (x = the last step's dv,
 * products in element_out), r = b - q, z = M^-1 r, d = z; bb, rr, rz; and whether the warm
 * start is already good enough (b = 0 counts as converged: the state update then uses
 * dv = 0, the exact solution). */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_start(uint S, uint node_count, __global const real* c,
              __global const int* incidence_offsets, __global const int* incidence,
              __global const int* ligament_offsets, __global const int* ligament_of_node,
              __global const real* ligament_k, __global const real* control_k,
              __global const real* mass, __global const real* element_out,
              __global const real* b, __global const real* inverse_diagonal,
              __global const real* x, __global real* r, __global real* z, __global real* d,
              __global real* bb, __global real* rr, __global real* rz, __global uint* active,
              __global uint* converged, __global int* iterations) {
  __local real scratch[SF_GROUP_SIZE];
  uint s = get_group_id(0);
  real sum_bb = (real)0;
  real sum_rr = (real)0;
  real sum_rz = (real)0;
  for (uint n = get_local_id(0); n < node_count; n += SF_GROUP_SIZE) {
    real spring = sf_node_spring(ligament_offsets, ligament_of_node, ligament_k, control_k, n, s, S);
    real m = sf_solver_mass(mass[n], spring);
    SF_UNROLL
    for (int k = 0; k < 3; ++k) {
      size_t row = ((size_t)3 * n + k) * S + s;
      real q = sf_system_row(c, element_out, incidence_offsets, incidence, spring, m, x, n, k, s, S);
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
  sum_bb = sf_group_sum(scratch, sum_bb);
  sum_rr = sf_group_sum(scratch, sum_rr);
  sum_rz = sf_group_sum(scratch, sum_rz);
  if (get_local_id(0) == 0) {
    int done = sum_bb == (real)0 || sum_rr <= c[SF_CG_TOLERANCE2] * sum_bb;
    bb[s] = sum_bb;
    rr[s] = sum_rr;
    rz[s] = sum_rz;
    active[s] = done ? 0u : 1u;
    converged[s] = done ? 1u : 0u;
    iterations[s] = 0;
  }
}

/* One CG iteration of one sigma point, given q = A d (node_product): alpha = rz / d.q, x += alpha d, r -= alpha q, z = M^-1 r, then the convergence
 * test (|r|^2 <= tol^2 |b|^2), the cap, breakdown (a residual that is not finite: the matrix
 * is not SPD or the input held a NaN), and d = z + beta d. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_iteration(uint S, uint node_count, int max_iterations, __global const real* c,
                  __global const real* inverse_diagonal, __global real* x, __global real* r,
                  __global real* z, __global real* d, __global const real* q,
                  __global const real* bb,
                  __global real* rr, __global real* rz, __global uint* active,
                  __global uint* converged, __global int* iterations) {
  __local real scratch[SF_GROUP_SIZE];
  uint s = get_group_id(0);
  if (!active[s]) return; /* the same for the whole group: no barrier is left waiting */
  int count = iterations[s] + 1;
  real rz_old = rz[s];
  uint first = get_local_id(0);

  real sum_dq = (real)0;
  for (uint n = first; n < node_count; n += SF_GROUP_SIZE) {
    SF_UNROLL
    for (int k = 0; k < 3; ++k) {
      size_t row = ((size_t)3 * n + k) * S + s;
      sum_dq += d[row] * q[row];
    }
  }
  real alpha = rz_old / sf_group_sum(scratch, sum_dq);

  real sum_rr = (real)0;
  real sum_rz = (real)0;
  for (uint n = first; n < node_count; n += SF_GROUP_SIZE) {
    SF_UNROLL
    for (int k = 0; k < 3; ++k) {
      size_t row = ((size_t)3 * n + k) * S + s;
      x[row] += alpha * d[row];
      real ri = r[row] - alpha * q[row];
      real zi = inverse_diagonal[row] * ri;
      r[row] = ri;
      z[row] = zi;
      sum_rr += ri * ri;
      sum_rz += ri * zi;
    }
  }
  sum_rr = sf_group_sum(scratch, sum_rr);
  sum_rz = sf_group_sum(scratch, sum_rz);

  int done = sum_rr <= c[SF_CG_TOLERANCE2] * bb[s];
  int stop = done || !isfinite(sum_rr) || count >= max_iterations;
  barrier(CLK_GLOBAL_MEM_FENCE); /* everyone has read the old scalars before they change */
  if (first == 0) {
    iterations[s] = count;
    rr[s] = sum_rr;
    rz[s] = sum_rz;
    if (done) converged[s] = 1u;
    if (stop) active[s] = 0u;
  }
  if (stop) return;
  real beta = sum_rz / rz_old;
  for (uint n = first; n < node_count; n += SF_GROUP_SIZE) {
    SF_UNROLL
    for (int k = 0; k < 3; ++k) {
      size_t row = ((size_t)3 * n + k) * S + s;
      d[row] = z[row] + beta * d[row];
    }
  }
}
