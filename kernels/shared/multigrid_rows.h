/* multigrid_rows.h: the rows of the multigrid V-cycle (host/reference/nested_multigrid.h, the
 * same arithmetic) that OpenCL's multigrid.cl and Vulkan's multigrid.comp run for every sigma
 * point at once, a work-item per (row, sigma point), at `at` = row S + s of the vectors. The
 * matrices are the representative's in CSR (row_start, columns, values), shared by the sigma
 * points; at the finest level each sigma point adds its own diagonal `own` (its springs
 * against the representative's: the shift) to A and D. The macros take the buffers' names. */
#ifndef SIGMAFEM_MULTIGRID_ROWS_H
#define SIGMAFEM_MULTIGRID_ROWS_H

#include "dialect.h"

/* sum += (M x)_row for sigma point s. */
#define SF_MG_CSR_ROW(sum, S, s, row, row_start_, columns_, values_, x_)                    \
  for (int k_ = SF_LOAD(row_start_, row); k_ < SF_LOAD(row_start_, (row) + 1u); ++k_)    \
    sum += SF_LOAD(values_, k_) * x_[SF_INDEX(SF_LOAD(columns_, k_)) * (S) + (s)];

/* Chebyshev step k of a smoothing (steps: [2k] previous, [2k + 1] residual): r = b - (A + own)
 * x_in (b alone from zero: x_in = 0), p_out = previous p_in + residual r / (D + own), x_out =
 * x_in + p_out. x and p go from one buffer to another: every row of x_in is read by its
 * neighbours. */
#define SF_MG_SMOOTH_ROW(at, row, s, S, k, from_zero, own, row_start_, columns_, values_,    \
                         diagonal_, steps_, b_, x_in_, p_in_, x_out_, p_out_)               \
  {                                                                                         \
    SF_REAL r_ = b_[at];                                                                    \
    SF_REAL x_ = SF_LIT(0);                                                                 \
    if (!(from_zero)) {                                                                     \
      x_ = x_in_[at];                                                                       \
      SF_REAL product_ = SF_LIT(0);                                                         \
      SF_MG_CSR_ROW(product_, S, s, row, row_start_, columns_, values_, x_in_)              \
      r_ -= product_ + (own) * x_;                                                          \
    }                                                                                       \
    SF_REAL p_ = SF_LOAD(steps_, 2u * (k) + 1u) * r_ / (SF_LOAD(diagonal_, row) + (own));   \
    if ((k) > 0u) p_ += SF_LOAD(steps_, 2u * (k)) * p_in_[at]; /* step 0 has no previous */ \
    p_out_[at] = p_;                                                                        \
    x_out_[at] = x_ + p_;                                                                   \
  }

/* r = b - (A + own) x. */
#define SF_MG_RESIDUAL_ROW(at, row, s, S, own, row_start_, columns_, values_, b_, x_, r_) \
  {                                                                                       \
    SF_REAL product_ = SF_LIT(0);                                                         \
    SF_MG_CSR_ROW(product_, S, s, row, row_start_, columns_, values_, x_)                 \
    r_[at] = b_[at] - product_ - (own) * x_[at];                                          \
  }

/* y = M x, or y += M x (accumulate): the restriction, the prolongation, the coarsest inverse. */
#define SF_MG_PRODUCT_ROW(at, row, s, S, accumulate, row_start_, columns_, values_, x_, y_) \
  {                                                                                         \
    SF_REAL product_ = SF_LIT(0);                                                           \
    SF_MG_CSR_ROW(product_, S, s, row, row_start_, columns_, values_, x_)                   \
    y_[at] = (accumulate) ? y_[at] + product_ : product_;                                   \
  }

#endif /* SIGMAFEM_MULTIGRID_ROWS_H */
