/* multigrid: NestedMultigrid's V-cycle (host/reference/nested_multigrid.h, the same
 * arithmetic) for every sigma point at once, CG's preconditioner in the GPU form: a work-item
 * per (row, sigma point), vectors [row S + s] as the ensemble's. The matrices are the
 * representative's, shared by the sigma points, in CSR (row_start, columns, values); at the
 * finest level each sigma point adds its own diagonal `shift` (its springs against the
 * representative's) to A and D. The host's OpenClMultigrid (host/opencl/opencl_multigrid.cpp)
 * enqueues these kernels level by level. */
#include "ensemble_layout.h"

/* Row `row` of M x for sigma point s. */
static inline real sf_csr_row(uint S, uint s, uint row, __global const int* row_start,
                              __global const int* columns, __global const real* values,
                              __global const real* x) {
  real sum = (real)0;
  for (int k = row_start[row]; k < row_start[row + 1]; ++k)
    sum += values[k] * x[(size_t)columns[k] * S + s];
  return sum;
}

/* Chebyshev step k of a smoothing (steps: [2k] previous, [2k + 1] residual): r = b - A x_in
 * (b alone from zero: x_in = 0), p_out = previous p_in + residual D^-1 r, x_out = x_in + p_out.
 * x and p go from one buffer to another: every row of x_in is read by its neighbours. */
__kernel void mg_smooth(uint S, uint rows, uint k, uint from_zero, uint shifted,
                        __global const int* row_start, __global const int* columns,
                        __global const real* values, __global const real* diagonal,
                        __global const real* steps, __global const real* shift,
                        __global const real* b, __global const real* x_in,
                        __global const real* p_in, __global real* x_out, __global real* p_out) {
  size_t at = get_global_id(0);
  if (at >= (size_t)rows * S) return;
  uint row = (uint)(at / S), s = (uint)(at % S);
  real own = shifted ? shift[at] : (real)0;
  real r = b[at];
  real x = (real)0;
  if (!from_zero) {
    x = x_in[at];
    r -= sf_csr_row(S, s, row, row_start, columns, values, x_in) + own * x;
  }
  real p = steps[2 * k + 1] * r / (diagonal[row] + own);
  if (k > 0) p += steps[2 * k] * p_in[at]; /* step 0 has no previous p */
  p_out[at] = p;
  x_out[at] = x + p;
}

/* r = b - A x, with the shift at the finest level. */
__kernel void mg_residual(uint S, uint rows, uint shifted, __global const int* row_start,
                          __global const int* columns, __global const real* values,
                          __global const real* shift, __global const real* b,
                          __global const real* x, __global real* r) {
  size_t at = get_global_id(0);
  if (at >= (size_t)rows * S) return;
  uint row = (uint)(at / S), s = (uint)(at % S);
  real own = shifted ? shift[at] : (real)0;
  r[at] = b[at] - sf_csr_row(S, s, row, row_start, columns, values, x) - own * x[at];
}

/* y = M x, or y += M x (accumulate): the restriction, the prolongation, the coarsest level's
 * inverse. */
__kernel void mg_product(uint S, uint rows, uint accumulate, __global const int* row_start,
                         __global const int* columns, __global const real* values,
                         __global const real* x, __global real* y) {
  size_t at = get_global_id(0);
  if (at >= (size_t)rows * S) return;
  uint row = (uint)(at / S), s = (uint)(at % S);
  real sum = sf_csr_row(S, s, row, row_start, columns, values, x);
  y[at] = accumulate ? y[at] + sum : sum;
}
