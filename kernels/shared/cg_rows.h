/* cg_rows.h: the rows and the stop test of the Jacobi-preconditioned conjugate gradient that
 * every device back end runs for all sigma points at once (conjugate_gradient.cl and .comp;
 * host: host/reference/conjugate_gradient.h, the same rule |r| <= tolerance |b|). The row
 * macros take the buffers' names (kernel arguments in OpenCL C, storage buffers in GLSL),
 * the row's index `at` and the sums they add to; each back end walks the rows its own way
 * (a work-group per sigma point or per partition on a GPU, a block of sigma points per
 * work-item on a CPU) and sums in a fixed order. */
#ifndef SIGMAFEM_CG_ROWS_H
#define SIGMAFEM_CG_ROWS_H

#include "dialect.h"

/* The warm start's row, with q = A x there: r = b - q, z = M^-1 r, d = z; b.b, r.r, r.z. */
#define SF_CG_START_ROW(at, q_value, b_, inverse_diagonal_, r_, z_, d_, sum_bb, sum_rr, sum_rz) \
  {                                                                                            \
    SF_REAL bi_ = SF_LOAD(b_, at);                                                             \
    SF_REAL ri_ = bi_ - (q_value);                                                             \
    SF_REAL zi_ = SF_LOAD(inverse_diagonal_, at) * ri_;                                        \
    r_[at] = ri_;                                                                              \
    z_[at] = zi_;                                                                              \
    d_[at] = zi_;                                                                              \
    sum_bb += bi_ * bi_;                                                                       \
    sum_rr += ri_ * ri_;                                                                       \
    sum_rz += ri_ * zi_;                                                                       \
  }

/* The same without z and d, where a factor forms them after the start (OpenCL's SF_FACTOR,
 * Vulkan's factor_solve): r = b - q; b.b, r.r. */
#define SF_CG_START_R_ROW(at, q_value, b_, r_, sum_bb, sum_rr) \
  {                                                            \
    SF_REAL bi_ = SF_LOAD(b_, at);                             \
    SF_REAL ri_ = bi_ - (q_value);                             \
    r_[at] = ri_;                                              \
    sum_bb += bi_ * bi_;                                       \
    sum_rr += ri_ * ri_;                                       \
  }

/* An iteration's row, with q = A d there (q_value: its value at the row): x += alpha d,
 * r -= alpha q, z = M^-1 r; r.r, r.z. */
#define SF_CG_UPDATE_ROW(at, alpha, q_value, x_, r_, z_, d_, inverse_diagonal_, sum_rr, sum_rz) \
  {                                                                                             \
    x_[at] += (alpha) * d_[at];                                                                 \
    SF_REAL ri_ = r_[at] - (alpha) * (q_value);                                                 \
    SF_REAL zi_ = SF_LOAD(inverse_diagonal_, at) * ri_;                                         \
    r_[at] = ri_;                                                                               \
    z_[at] = zi_;                                                                               \
    sum_rr += ri_ * ri_;                                                                        \
    sum_rz += ri_ * zi_;                                                                        \
  }

/* The same without z, where a factor forms z after the update (OpenCL's SF_FACTOR, Vulkan's
 * factor_solve): x += alpha d, r -= alpha q; r.r. */
#define SF_CG_UPDATE_XR_ROW(at, alpha, q_value, x_, r_, d_, sum_rr) \
  {                                                                 \
    x_[at] += (alpha) * d_[at];                                     \
    SF_REAL ri_ = r_[at] - (alpha) * (q_value);                     \
    r_[at] = ri_;                                                   \
    sum_rr += ri_ * ri_;                                            \
  }

/* After the warm start: an overflowed load (|b|^2 not finite) would pass the stop test as
 * inf <= inf, so it is a breakdown, neither converged nor iterating, as in the CPU
 * reference; b = 0 counts as converged (the state update then uses dv = 0, the exact
 * solution). */
SF_FN bool sf_cg_start_breakdown(SF_REAL bb, SF_REAL rr) {
  return !SF_ISFINITE(bb) || !SF_ISFINITE(rr);
}
SF_FN bool sf_cg_start_converged(bool breakdown, SF_REAL bb, SF_REAL rr, SF_REAL tolerance2) {
  return !breakdown && (bb == SF_LIT(0) || rr <= tolerance2 * bb);
}

/* After an iteration: converged when |r|^2 <= tol^2 |b|^2; it stops there, at a breakdown (a
 * residual that is not finite: the matrix is not SPD or the input held a NaN) or when
 * `count` products reach the cap. */
SF_FN bool sf_cg_converged(SF_REAL rr, SF_REAL tolerance2, SF_REAL bb) {
  return rr <= tolerance2 * bb;
}
SF_FN bool sf_cg_stops(bool converged, SF_REAL rr, int count, int max_iterations) {
  return converged || !SF_ISFINITE(rr) || count >= max_iterations;
}

#endif /* SIGMAFEM_CG_ROWS_H */
