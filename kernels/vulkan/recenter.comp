/* recenter: the ROUKF's re-sampling of every sigma point's state around the corrected
 * estimate, one dof row per invocation, done where the states are (kernels/shared/recenter.h;
 * as kernels/opencl/recenter.cl). */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"
#include "recenter.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
/* scalars: [0] alpha, [1 .. p] the correction. directions, weights: p x S, [j * S + s]. */
layout(std430, binding = SF_RECENTER_RECENTER_SCALARS) restrict readonly buffer Scalars { real scalars[]; };
layout(std430, binding = SF_RECENTER_DIRECTIONS) restrict readonly buffer Directions { real directions[]; };
layout(std430, binding = SF_RECENTER_WEIGHTS) restrict readonly buffer Weights { real weights[]; };
layout(std430, binding = SF_RECENTER_X) restrict buffer X { real x[]; };
layout(std430, binding = SF_RECENTER_V) restrict buffer V { real v[]; };

void main() {
  uint S = sf_push.S;
  uint p = sf_push.p;
  uint row = sf_global_id();
  if (row >= sf_push.count) return;
  uint base = row * S;
  real correction[SF_MAX_PARAMETERS];
  real column[SF_MAX_PARAMETERS];   /* sigma point s's directions, then its weights */
  real L[SF_MAX_PARAMETERS];
  real Lv[SF_MAX_PARAMETERS];
  for (uint j = 0u; j < p; ++j) {
    correction[j] = scalars[1u + j];
    L[j] = real(0);
    Lv[j] = real(0);
  }
  real x0 = x[base];
  real v0 = v[base];
  real sum = real(0);
  real sum_v = real(0);
  for (uint s = 0u; s < S; ++s) {
    for (uint j = 0u; j < p; ++j) column[j] = directions[j * S + s];
    real dx = x[base + s] - x0;
    real dv = v[base + s] - v0;
    sum += dx;
    sum_v += dv;
    sf_recenter_add(dx, column, p, L);
    sf_recenter_add(dv, column, p, Lv);
  }
  real x_hat = sf_recentred_mean(x0, scalars[0], sum, correction, p, L);
  real v_hat = sf_recentred_mean(v0, scalars[0], sum_v, correction, p, Lv);
  for (uint s = 0u; s < S; ++s) {
    for (uint j = 0u; j < p; ++j) column[j] = weights[j * S + s];
    x[base + s] = sf_resampled(x_hat, L, column, p);
    v[base + s] = sf_resampled(v_hat, Lv, column, p);
  }
}
