/* observation_gather: the observed points' positions of every sigma point, y[(3 k + axis) S + s]
 * (kernels/shared/observation_gather.h). The only per-step read-back of the state. */
#include "ensemble_layout.h"
#include "observation_gather.h"

__kernel void observation_gather(uint S, uint observed_count, __global const int* nodes,
                                 __global const real* weights, __global const real* x,
                                 __global real* y) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)3 * observed_count * S) return;
  uint s = (uint)(gid % S);
  uint row = (uint)(gid / S);
  uint k = row / 3;
  uint axis = row % 3;
  real weight[4];
  real corner[4];
  SF_LOAD_OBSERVED_POINT(nodes, weights, x, k, axis, s, S, weight, corner)
  y[gid] = sf_observed_coordinate(weight, corner);
}
