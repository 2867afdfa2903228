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

/* L_j += dx I_js for sigma point s's difference dx from sigma point 0 and its directions. */
SF_FN void sf_recenter_add(SF_REAL dx, SF_IN(direction, SF_MAX_PARAMETERS), uint p,
                           SF_INOUT(L, SF_MAX_PARAMETERS)) {
  for (uint j = 0; j < p; ++j) L[j] += dx * direction[j];
}

/* X_hat from sigma point 0's value x0 and the sum of the differences; scales L by alpha. */
SF_FN SF_REAL sf_recentred_mean(SF_REAL x0, SF_REAL alpha, SF_REAL sum,
                                SF_IN(correction, SF_MAX_PARAMETERS), uint p,
                                SF_INOUT(L, SF_MAX_PARAMETERS)) {
  SF_REAL mean = x0 + alpha * sum;
  for (uint j = 0; j < p; ++j) {
    L[j] *= alpha;
    mean += L[j] * correction[j];
  }
  return mean;
}

/* Sigma point s's new value from X_hat, L and its weights W_js. */
SF_FN SF_REAL sf_resampled(SF_REAL mean, SF_IN(L, SF_MAX_PARAMETERS),
                           SF_IN(weight, SF_MAX_PARAMETERS), uint p) {
  SF_REAL value = mean;
  for (uint j = 0; j < p; ++j) value += L[j] * weight[j];
  return value;
}

#endif /* SIGMAFEM_RECENTER_H */
