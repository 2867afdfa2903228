/* state_update: v += dv, x += h v for every row of every sigma point (state_update.h). One
 * invocation per (row, sigma); or, compiled with SF_SIGMA_QUADS (state_update_quads), per row
 * and four sigma points (sigma_quads.h: a vec4 store of each where four scalar ones were). */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"
#include "state_update.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
SF_READ_REALS(SF_STATE_UPDATE_CONSTANTS, c)
#if defined(SF_SIGMA_QUADS)
#  include "sigma_quads.h"
SF_READ_QUADS(SF_STATE_UPDATE_BB, bb)
layout(std430, binding = SF_STATE_UPDATE_DV) restrict buffer DV { SF_SCALAR4 dv[]; };
layout(std430, binding = SF_STATE_UPDATE_X) restrict buffer X { SF_SCALAR4 x[]; };
layout(std430, binding = SF_STATE_UPDATE_V) restrict buffer V { SF_SCALAR4 v[]; };

void main() {
  uint Q = sf_push.S / 4u;
  uint gid = sf_global_id();   /* quad (row, q) of the per-dof arrays: [row Q + q] */
  if (gid >= sf_push.count * Q) return;
  SF_STATE_UPDATE_ROW(gid, SF_QUAD(bb, gid % Q), SF_REAL(SF_LOAD(c, SF_H)), dv, x, v)
}
#else
SF_READ_REALS(SF_STATE_UPDATE_BB, bb)
layout(std430, binding = SF_STATE_UPDATE_DV) restrict buffer DV { real dv[]; };
layout(std430, binding = SF_STATE_UPDATE_X) restrict buffer X { real x[]; };
layout(std430, binding = SF_STATE_UPDATE_V) restrict buffer V { real v[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  SF_STATE_UPDATE_ROW(gid, SF_LOAD(bb, gid % S), SF_LOAD(c, SF_H), dv, x, v)
}
#endif
