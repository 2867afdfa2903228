/* recenter.h: the ROUKF's re-sampling of one dof row of every sigma point's state around the
 * corrected estimate (the recenter kernels of recenter.cl and .comp; host: CpuEnsemble::recenter,
 * filter/ensemble.h, struct Recentering). With X_s the row's sigma states and I_s the
 * directions:
 *   mean = alpha sum_s X_s,  L_j = alpha sum_s X_s I_js,  X_hat = mean + L correction,
 *   X_s <- X_hat + sum_j L_j W_js  (W = C I, formed on the host),
 * for the positions and the velocities alike (the state of a dynamic simulation is both).
 * The sums are taken relative to sigma point 0: the directions sum to zero and the weights
 * to one, so this is the same in exact arithmetic, and in float32 it keeps the rounding at
 * the size of the spread between sigma points rather than of the organ's position. */
#ifndef SIGMAFEM_RECENTER_H
#define SIGMAFEM_RECENTER_H

#include "dialect.h"
#include "step_constants.h"

/* Re-samples the row whose S values start at x[base] and v[base], for p parameters.
 * scalars: [0] alpha, [1 .. p] the correction; directions, weights: p x S, [j * S + s].
 * L and Lv: the caller's arrays of at least p reals (SF_MAX_PARAMETERS). A macro, not
 * functions: GLSL passes arrays by value, and lavapipe spent 7.6 ms of the liver's filter
 * step copying them (bench/RESULTS.md, stop 50). */
#define SF_RECENTER_ROW(scalars, directions, weights, x, v, base, S, p, L, Lv)         \
  {                                                                                  \
    for (uint j_ = 0u; j_ < (p); ++j_) {                                             \
      L[j_] = SF_LIT(0);                                                             \
      Lv[j_] = SF_LIT(0);                                                            \
    }                                                                                \
    SF_REAL x0_ = x[base];                                                           \
    SF_REAL v0_ = v[base];                                                           \
    SF_REAL sum_ = SF_LIT(0);                                                        \
    SF_REAL sum_v_ = SF_LIT(0);                                                      \
    for (uint s_ = 0u; s_ < (S); ++s_) {                                             \
      SF_REAL dx_ = x[(base) + s_] - x0_;                                            \
      SF_REAL dv_ = v[(base) + s_] - v0_;                                            \
      sum_ += dx_;                                                                   \
      sum_v_ += dv_;                                                                 \
      for (uint j_ = 0u; j_ < (p); ++j_) {                                           \
        SF_REAL direction_ = SF_LOAD(directions, j_ * (S) + s_);                     \
        L[j_] += dx_ * direction_;                                                   \
        Lv[j_] += dv_ * direction_;                                                  \
      }                                                                              \
    }                                                                                \
    SF_REAL alpha_ = SF_LOAD(scalars, 0u);                                           \
    SF_REAL x_hat_ = x0_ + alpha_ * sum_;                                            \
    SF_REAL v_hat_ = v0_ + alpha_ * sum_v_;                                          \
    for (uint j_ = 0u; j_ < (p); ++j_) {                                             \
      SF_REAL correction_ = SF_LOAD(scalars, 1u + j_);                               \
      L[j_] *= alpha_;                                                               \
      Lv[j_] *= alpha_;                                                              \
      x_hat_ += L[j_] * correction_;                                                 \
      v_hat_ += Lv[j_] * correction_;                                                \
    }                                                                                \
    for (uint s_ = 0u; s_ < (S); ++s_) {                                             \
      SF_REAL x_new_ = x_hat_;                                                       \
      SF_REAL v_new_ = v_hat_;                                                       \
      for (uint j_ = 0u; j_ < (p); ++j_) {                                           \
        SF_REAL weight_ = SF_LOAD(weights, j_ * (S) + s_);                           \
        x_new_ += L[j_] * weight_;                                                   \
        v_new_ += Lv[j_] * weight_;                                                  \
      }                                                                              \
      x[(base) + s_] = x_new_;                                                       \
      v[(base) + s_] = v_new_;                                                       \
    }                                                                                \
  }

#endif /* SIGMAFEM_RECENTER_H */
