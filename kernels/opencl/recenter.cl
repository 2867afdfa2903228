/* recenter: the ROUKF's re-sampling of every sigma point's state around the corrected
 * estimate, done where the states are (host: CpuEnsemble::recenter; filter/ensemble.h,
 * struct Recentering). Per dof row, with X_s the sigma states and I_s the directions:
 *   mean = alpha sum_s X_s,  L_j = alpha sum_s X_s I_js,  X_hat = mean + L correction,
 *   X_s <- X_hat + sum_j L_j W_js  (W = C I, formed on the host),
 * and the same for the velocities V (the state of a dynamic simulation is both).
 * The sums are taken relative to sigma point 0: the directions sum to zero and the weights
 * to one, so this is the same in exact arithmetic, and in float32 it keeps the rounding at
 * the size of the spread between sigma points rather than of the organ's position. */
#include "ensemble_layout.h"

#ifndef SF_MAX_PARAMETERS
#  define SF_MAX_PARAMETERS 16
#endif

/* scalars: [0] alpha, [1 .. p] the correction. directions, weights: p x S, [j * S + s]. */
__kernel void recenter(uint S, uint rows, uint p, __global const real* scalars,
                       __global const real* directions, __global const real* weights,
                       __global real* x, __global real* v) {
  size_t row = get_global_id(0);
  if (row >= rows) return;
  __global real* xr = x + row * S;
  __global real* vr = v + row * S;
  real alpha = scalars[0];
  real x0 = xr[0];
  real v0 = vr[0];
  real mean = (real)0;
  real velocity = (real)0;
  real L[SF_MAX_PARAMETERS];
  real Lv[SF_MAX_PARAMETERS];
  for (uint j = 0; j < p; ++j) {
    L[j] = (real)0;
    Lv[j] = (real)0;
  }
  for (uint s = 0; s < S; ++s) {
    real dx = xr[s] - x0;
    mean += dx;
    real dv = vr[s] - v0;
    velocity += dv;
    for (uint j = 0; j < p; ++j) {
      L[j] += dx * directions[j * S + s];
      Lv[j] += dv * directions[j * S + s];
    }
  }
  real x_hat = x0 + alpha * mean;
  real v_hat = v0 + alpha * velocity;
  for (uint j = 0; j < p; ++j) {
    L[j] *= alpha;
    Lv[j] *= alpha;
    x_hat += L[j] * scalars[1 + j];
    v_hat += Lv[j] * scalars[1 + j];
  }
  for (uint s = 0; s < S; ++s) {
    real xs = x_hat;
    real vs = v_hat;
    for (uint j = 0; j < p; ++j) {
      xs += L[j] * weights[j * S + s];
      vs += Lv[j] * weights[j * S + s];
    }
    xr[s] = xs;
    vr[s] = vs;
  }
}
