/* state_update: v += dv, x += h v for every row of every sigma point (state_update.h). */
#include "ensemble_layout.h"
#include "state_update.h"

__kernel void state_update(uint S, uint rows, __global const real* c, __global const real* bb,
                           __global real* dv, __global real* x, __global real* v) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)rows * S) return;
  SF_STATE_UPDATE_ROW(gid, bb[gid % S], c[SF_H], dv, x, v)
}
