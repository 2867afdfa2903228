/* multigrid: NestedMultigrid's V-cycle (host/reference/nested_multigrid.h) for every sigma
 * point at once, CG's preconditioner in the GPU form: a work-item per (row, sigma point), the
 * rows of kernels/shared/multigrid_rows.h. The host's OpenClMultigrid
 * (host/opencl/opencl_multigrid.cpp) enqueues these kernels level by level. */
#include "ensemble_layout.h"
#include "multigrid_rows.h"

/* A Chebyshev step of a smoothing (SF_MG_SMOOTH_ROW); `shifted`: the finest level. */
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
  SF_MG_SMOOTH_ROW(at, row, s, S, k, from_zero, own, row_start, columns, values, diagonal, steps, b,
                   x_in, p_in, x_out, p_out)
}

/* r = b - A x (SF_MG_RESIDUAL_ROW). */
__kernel void mg_residual(uint S, uint rows, uint shifted, __global const int* row_start,
                          __global const int* columns, __global const real* values,
                          __global const real* shift, __global const real* b,
                          __global const real* x, __global real* r) {
  size_t at = get_global_id(0);
  if (at >= (size_t)rows * S) return;
  uint row = (uint)(at / S), s = (uint)(at % S);
  real own = shifted ? shift[at] : (real)0;
  SF_MG_RESIDUAL_ROW(at, row, s, S, own, row_start, columns, values, b, x, r)
}

/* y = M x or y += M x (SF_MG_PRODUCT_ROW). */
__kernel void mg_product(uint S, uint rows, uint accumulate, __global const int* row_start,
                         __global const int* columns, __global const real* values,
                         __global const real* x, __global real* y) {
  size_t at = get_global_id(0);
  if (at >= (size_t)rows * S) return;
  uint row = (uint)(at / S), s = (uint)(at % S);
  SF_MG_PRODUCT_ROW(at, row, s, S, accumulate, row_start, columns, values, x, y)
}
