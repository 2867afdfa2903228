/* recenter: the ROUKF's re-sampling of every sigma point's state around the corrected
 * estimate, one dof row per work-item, done where the states are (kernels/shared/recenter.h). */
#include "ensemble_layout.h"
#include "recenter.h"

/* scalars: [0] alpha, [1 .. p] the correction. directions, weights: p x S, [j * S + s]. */
__kernel void recenter(uint S, uint rows, uint p, __global const real* scalars,
                       __global const real* directions, __global const real* weights,
                       __global real* x, __global real* v) {
  size_t row = get_global_id(0);
  if (row >= rows) return;
  __global real* xr = x + row * S;
  __global real* vr = v + row * S;
  real correction[SF_MAX_PARAMETERS];
  real column[SF_MAX_PARAMETERS];   /* sigma point s's directions, then its weights */
  real L[SF_MAX_PARAMETERS];
  real Lv[SF_MAX_PARAMETERS];
  for (uint j = 0; j < p; ++j) {
    correction[j] = scalars[1 + j];
    L[j] = (real)0;
    Lv[j] = (real)0;
  }
  real x0 = xr[0];
  real v0 = vr[0];
  real sum = (real)0;
  real sum_v = (real)0;
  for (uint s = 0; s < S; ++s) {
    for (uint j = 0; j < p; ++j) column[j] = directions[j * S + s];
    real dx = xr[s] - x0;
    real dv = vr[s] - v0;
    sum += dx;
    sum_v += dv;
    sf_recenter_add(dx, column, p, L);
    sf_recenter_add(dv, column, p, Lv);
  }
  real x_hat = sf_recentred_mean(x0, scalars[0], sum, correction, p, L);
  real v_hat = sf_recentred_mean(v0, scalars[0], sum_v, correction, p, Lv);
  for (uint s = 0; s < S; ++s) {
    for (uint j = 0; j < p; ++j) column[j] = weights[j * S + s];
    xr[s] = sf_resampled(x_hat, L, column, p);
    vr[s] = sf_resampled(v_hat, Lv, column, p);
  }
}
