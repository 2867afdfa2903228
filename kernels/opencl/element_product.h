/* element_product.h: one element's tangent product for one sigma point, y_e = R K_e R^T d_e,
 * written to its 12 corner outputs (ensemble_layout.h). Used by the element_product kernel
 * (a block of sigma points per work-item) and by cg_solve (a sigma point per work-group). The
 * caller loads the element's rest state and nodes, which the blocked kernel does once for
 * all its sigma points. */
#ifndef SIGMAFEM_ELEMENT_PRODUCT_H
#define SIGMAFEM_ELEMENT_PRODUCT_H

#include "ensemble_layout.h"

static inline __attribute__((always_inline)) void sf_element_product_of(const real grad[12], real vlambda, real vmu,
                                         const int corner_nodes[4],
                                         __global const real* restrict frames,
                                         __global const real* restrict d, uint e, uint s, uint S,
                                         __global real* restrict out) {
  real frame[9];
  real corner[12];
  real product[12];
  sf_load_frame(frames, e, s, S, frame);
  sf_gather_corners(d, corner_nodes, s, S, corner);
  sf_element_product(frame, grad, vlambda, vmu, corner, product);
  sf_store_corners(out, e, s, S, product);
}

#endif /* SIGMAFEM_ELEMENT_PRODUCT_H */
