/* observation_gather.h: one coordinate of an observed point of one sigma point (the
 * observation_gather kernels of observation_gather.cl and .comp; host:
 * CpuEnsemble::predicted_observations). A point is sum_c w_c x(node_c) over its four corners
 * (host/model/observed_points.h); a node is itself with weight 1 and three zero weights, its
 * value bit for bit. */
#ifndef SIGMAFEM_OBSERVATION_GATHER_H
#define SIGMAFEM_OBSERVATION_GATHER_H

#include "dialect.h"

SF_FN SF_REAL sf_observed_coordinate(SF_IN(weight, 4), SF_IN(corner, 4)) {
  SF_REAL value = SF_LIT(0);
  for (int c = 0; c < 4; ++c) value += weight[c] * corner[c];
  return value;
}

/* Observed point k's four weights and its corners' coordinate `axis` for sigma point s, from the
 * device buffers (4 corner nodes and weights per point; x sigma-innermost). */
#define SF_LOAD_OBSERVED_POINT(nodes, weights, x, k, axis, s, S, weight, corner)          \
  for (uint c_ = 0u; c_ < 4u; ++c_) {                                                     \
    weight[c_] = SF_LOAD(weights, 4u * (k) + c_);                                         \
    corner[c_] =                                                                          \
        SF_LOAD(x, (SF_INDEX(3u) * SF_INDEX(SF_LOAD(nodes, 4u * (k) + c_)) + (axis)) * (S) + (s)); \
  }

#endif /* SIGMAFEM_OBSERVATION_GATHER_H */
