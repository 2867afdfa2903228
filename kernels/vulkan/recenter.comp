/* recenter: the ROUKF's re-sampling of every sigma point's state around the corrected
 * estimate, done where the states are (as kernels/opencl/recenter.cl; host:
 * CpuEnsemble::recenter; filter/ensemble.h, struct Recentering). Per dof row, with X_s the
 * sigma states and I_s the directions:
 *   mean = alpha sum_s X_s,  L_j = alpha sum_s X_s I_js,  X_hat = mean + L correction,
 *   X_s <- X_hat + sum_j L_j W_js  (W = C I, formed on the host),
 * and the same for the velocities V (the state of a dynamic simulation is both).
 * The sums are taken relative to sigma point 0 (the directions sum to zero and the weights
 * to one), which keeps float32 rounding at the size of the spread between sigma points. */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"

#define SF_MAX_PARAMETERS 16

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
/* scalars: [0] alpha, [1 .. p] the correction. directions, weights: p x S, [j * S + s]. */
layout(std430, binding = 0) restrict readonly buffer Scalars { real scalars[]; };
layout(std430, binding = 1) restrict readonly buffer Directions { real directions[]; };
layout(std430, binding = 2) restrict readonly buffer Weights { real weights[]; };
layout(std430, binding = 3) restrict buffer X { real x[]; };
layout(std430, binding = 4) restrict buffer V { real v[]; };

void main() {
  uint S = sf_push.S;
  uint p = sf_push.p;
  uint row = sf_global_id();
  if (row >= sf_push.count) return;
  uint base = row * S;
  real alpha = scalars[0];
  real x0 = x[base];
  real v0 = v[base];
  real mean = real(0);
  real velocity = real(0);
  real L[SF_MAX_PARAMETERS];
  real Lv[SF_MAX_PARAMETERS];
  for (uint j = 0u; j < p; ++j) {
    L[j] = real(0);
    Lv[j] = real(0);
  }
  for (uint s = 0u; s < S; ++s) {
    real dx = x[base + s] - x0;
    mean += dx;
    real dv = v[base + s] - v0;
    velocity += dv;
    for (uint j = 0u; j < p; ++j) {
      L[j] += dx * directions[j * S + s];
      Lv[j] += dv * directions[j * S + s];
    }
  }
  real x_hat = x0 + alpha * mean;
  real v_hat = v0 + alpha * velocity;
  for (uint j = 0u; j < p; ++j) {
    L[j] *= alpha;
    Lv[j] *= alpha;
    x_hat += L[j] * scalars[1u + j];
    v_hat += Lv[j] * scalars[1u + j];
  }
  for (uint s = 0u; s < S; ++s) {
    real xs = x_hat;
    real vs = v_hat;
    for (uint j = 0u; j < p; ++j) {
      xs += L[j] * weights[j * S + s];
      vs += Lv[j] * weights[j * S + s];
    }
    x[base + s] = xs;
    v[base + s] = vs;
  }
}
