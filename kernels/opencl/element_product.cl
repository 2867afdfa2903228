/* element_product: y_e = R K_e R^T d_e for every element and sigma point, the cost of every
 * CG iteration (host: element_product in host/reference/corotational.h). Each element writes
 * its own 12 outputs; the node kernels (node_assembly.cl, conjugate_gradient.cl) sum them, so no atomics are needed and
 * the sums come out in the same order every run. */
#include "ensemble_layout.h"

__kernel void element_product(uint S, uint element_count, __global const int* nodes,
                              __global const real* rest, __global const real* frames,
                              __global const real* d, __global const uint* active,
                              __global real* out) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)element_count * S) return;
  uint s = (uint)(gid % S);
  if (!active[s]) return; /* this sigma point's CG is done */
  uint e = (uint)(gid / S);
  real grad[12];
  real vlambda;
  real vmu;
  real frame[9];
  real corner[12];
  real product[12];
  sf_load_rest(rest, e, grad, &vlambda, &vmu);
  sf_load_frame(frames, e, s, S, frame);
  sf_gather_corners(d, nodes, e, s, S, corner);
  sf_element_product(frame, grad, vlambda, vmu, corner, product);
  sf_store_corners(out, e, s, S, product);
}
