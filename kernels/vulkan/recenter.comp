/* recenter: the ROUKF's re-sampling of every sigma point's state around the corrected
 * estimate, one dof row per invocation, done where the states are (kernels/shared/recenter.h;
 * as kernels/opencl/recenter.cl). */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"
#include "recenter.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
/* S and p set at pipeline creation (specialization constants 0 and 1; 0: the push constants'),
 * so that the loops over them unroll and L and Lv stay in registers: lavapipe indexes a local
 * array by a lane's register one lane at a time (the liver at S = 4, p = 3: 62 -> 21 us;
 * bench/RESULTS.md, stop 58). */
layout(constant_id = 0) const uint SF_RECENTER_SIGMA_POINTS = 0u;
layout(constant_id = 1) const uint SF_RECENTER_PARAMETERS = 0u;
/* scalars: [0] alpha, [1 .. p] the correction. directions, weights: p x S, [j * S + s]. */
SF_READ_REALS(SF_RECENTER_RECENTER_SCALARS, scalars)
SF_READ_REALS(SF_RECENTER_DIRECTIONS, directions)
SF_READ_REALS(SF_RECENTER_WEIGHTS, weights)
layout(std430, binding = SF_RECENTER_X) restrict buffer X { real x[]; };
layout(std430, binding = SF_RECENTER_V) restrict buffer V { real v[]; };

void main() {
  uint S = SF_RECENTER_SIGMA_POINTS > 0u ? SF_RECENTER_SIGMA_POINTS : sf_push.S;
  uint p = SF_RECENTER_PARAMETERS > 0u ? SF_RECENTER_PARAMETERS : sf_push.p;
  uint row = sf_global_id();
  if (row >= sf_push.count) return;
  real L[SF_MAX_PARAMETERS];
  real Lv[SF_MAX_PARAMETERS];
  SF_RECENTER_ROW(scalars, directions, weights, x, v, row * S, S, p, L, Lv)
}
