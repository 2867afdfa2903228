/* observation_gather: the observed points' positions of every sigma point, y[(3 k + axis) S + s]
 * (host: CpuEnsemble::predicted_observations). Point k is sum_c w_c x(node_c) over its four
 * corners, nodes[4 k + c] and weights[4 k + c] (host/model/observed_points.h; a node is
 * itself with weight 1 and three zero weights: its value bit for bit). The only per-step
 * read-back of the state. */
#include "ensemble_layout.h"

__kernel void observation_gather(uint S, uint observed_count, __global const int* nodes,
                                 __global const real* weights, __global const real* x,
                                 __global real* y) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)3 * observed_count * S) return;
  uint s = (uint)(gid % S);
  uint row = (uint)(gid / S);
  uint k = row / 3;
  uint axis = row % 3;
  real value = (real)0;
  for (uint c = 0; c < 4; ++c)
    value += weights[4 * k + c] * x[((size_t)3 * nodes[4 * k + c] + axis) * S + s];
  y[gid] = value;
}
