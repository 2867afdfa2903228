/* element_product: y_e = R K_e R^T d_e for every element and sigma point, the cost of every
 * CG iteration (host: element_product in host/reference/corotational.h). Each element writes
 * its own 12 outputs; the node kernels (node_assembly.cl, conjugate_gradient.cl) sum them,
 * so no atomics are needed and the sums come out in the same order every run.
 *
 * A work-item takes one element and SF_SIGMA_BLOCK consecutive sigma points (ensemble_layout.h):
 * on a GPU one (element, sigma) each; on a CPU all of them, so that the element's rest
 * state is loaded once and the loop over sigma points, whose data are contiguous, is
 * vectorised by the compiler. */
#include "ensemble_layout.h"

__kernel void element_product(uint S, uint element_count, __global const int* restrict nodes,
                              __global const real* restrict rest, __global const real* restrict frames,
                              __global const real* restrict d, __global const uint* restrict active,
                              __global real* restrict out) {
  uint e;
  uint first;
  if (!sf_block_item(get_global_id(0), S, element_count, &e, &first)) return;
  real grad[12];
  real vlambda;
  real vmu;
  sf_load_rest(rest, e, grad, &vlambda, &vmu);
  int corner_nodes[4];
  sf_load_nodes(nodes, e, corner_nodes);
  for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) {
    uint s = first + b;
#if SF_SIGMA_BLOCK == 1
    if (!active[s]) return; /* this sigma point's CG is done */
#endif
    real frame[9];
    real corner[12];
    real product[12];
    sf_load_frame(frames, e, s, S, frame);
    sf_gather_corners(d, corner_nodes, s, S, corner);
    sf_element_product(frame, grad, vlambda, vmu, corner, product);
    sf_store_corners(out, e, s, S, product);
  }
}
