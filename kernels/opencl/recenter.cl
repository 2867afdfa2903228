/* recenter: the ROUKF's re-sampling of every sigma point's state around the corrected
 * estimate, one dof row per work-item, done where the states are (kernels/shared/recenter.h). */
#include "ensemble_layout.h"
#include "recenter.h"

/* scalars: [0] alpha, [1 .. p] the correction. directions, weights: p x S, [j * S + s]. */
__kernel void recenter(uint S, uint rows, uint p, __global const real* scalars,
                       __global const real* directions, __global const real* weights,
                       __global real* x, __global real* v) {
  size_t row = get_global_id(0);
  if (row >= rows) return;
  real L[SF_MAX_PARAMETERS];
  real Lv[SF_MAX_PARAMETERS];
  SF_RECENTER_ROW(scalars, directions, weights, x, v, row * S, S, p, L, Lv)
}
