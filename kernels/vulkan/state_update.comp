/* state_update: v += dv, x += h v for every sigma point (as kernels/opencl/state_update.cl).
 * A sigma point whose right-hand side was zero keeps dv = 0 (CG's exact answer). */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
layout(std430, binding = SF_STATE_UPDATE_CONSTANTS) restrict readonly buffer C { real c[]; };
layout(std430, binding = SF_STATE_UPDATE_BB) restrict readonly buffer BB { real bb[]; };
layout(std430, binding = SF_STATE_UPDATE_DV) restrict buffer DV { real dv[]; };
layout(std430, binding = SF_STATE_UPDATE_X) restrict buffer X { real x[]; };
layout(std430, binding = SF_STATE_UPDATE_V) restrict buffer V { real v[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint s = gid % S;
  if (bb[s] == real(0)) dv[gid] = real(0);
  real vi = v[gid] + dv[gid];
  v[gid] = vi;
  x[gid] += c[SF_H] * vi;
}
