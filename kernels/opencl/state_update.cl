/* state_update: v += dv, x += h v for every sigma point (host: ReferenceSimulation::step).
 * A sigma point whose right-hand side was zero keeps dv = 0 (CG's exact answer). */
#include "ensemble_layout.h"

__kernel void state_update(uint S, uint rows, __global const real* c, __global const real* bb,
                           __global real* dv, __global real* x, __global real* v) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)rows * S) return;
  uint s = (uint)(gid % S);
  if (bb[s] == (real)0) dv[gid] = (real)0;
  real vi = v[gid] + dv[gid];
  v[gid] = vi;
  x[gid] += c[SF_H] * vi;
}
