/* observation_gather: the observed nodes' positions of every sigma point, y[(3 k + axis) S + s]
 * (host: CpuEnsemble::predicted_observations). The only per-step read-back of the state. */
#include "ensemble_layout.h"

__kernel void observation_gather(uint S, uint observed_count, __global const int* observed,
                                 __global const real* x, __global real* y) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)3 * observed_count * S) return;
  uint s = (uint)(gid % S);
  uint row = (uint)(gid / S);
  uint k = row / 3;
  uint axis = row % 3;
  y[gid] = x[((size_t)3 * observed[k] + axis) * S + s];
}
