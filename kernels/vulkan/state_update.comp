/* state_update: v += dv, x += h v for every row of every sigma point (state_update.h). */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"
#include "state_update.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
SF_READ_REALS(SF_STATE_UPDATE_CONSTANTS, c)
SF_READ_REALS(SF_STATE_UPDATE_BB, bb)
layout(std430, binding = SF_STATE_UPDATE_DV) restrict buffer DV { real dv[]; };
layout(std430, binding = SF_STATE_UPDATE_X) restrict buffer X { real x[]; };
layout(std430, binding = SF_STATE_UPDATE_V) restrict buffer V { real v[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  SF_STATE_UPDATE_ROW(gid, gid % S, SF_LOAD(c, SF_H), bb, dv, x, v)
}
