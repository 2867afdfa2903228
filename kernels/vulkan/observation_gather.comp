/* observation_gather: the observed points' positions of every sigma point, y[(3 k + axis) S + s]
 * (kernels/shared/observation_gather.h; as kernels/opencl/observation_gather.cl). The only
 * per-step read-back of the state. */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"
#include "observation_gather.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
SF_READ_INTS(SF_OBSERVATION_GATHER_OBSERVED_NODES, nodes)
SF_READ_REALS(SF_OBSERVATION_GATHER_OBSERVED_WEIGHTS, weights)
SF_READ_REALS(SF_OBSERVATION_GATHER_X, x)
layout(std430, binding = SF_OBSERVATION_GATHER_OBSERVATIONS) restrict writeonly buffer Y { real y[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= 3u * sf_push.count * S) return;
  uint s = gid % S;
  uint row = gid / S;
  uint k = row / 3u;
  uint axis = row % 3u;
  real weight[4];
  real corner[4];
  SF_LOAD_OBSERVED_POINT(nodes, weights, x, k, axis, s, S, weight, corner)
  y[gid] = sf_observed_coordinate(weight, corner);
}
