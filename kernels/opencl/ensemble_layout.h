/* ensemble_layout.h: what every OpenCL kernel includes: the layout every back end shares
 * (kernels/shared/device_layout.h; a kernel's buffer arguments follow its slots there, after
 * its scalars) and the index helpers over its buffers. */
#ifndef SIGMAFEM_ENSEMBLE_LAYOUT_H
#define SIGMAFEM_ENSEMBLE_LAYOUT_H

#ifdef SF_USE_DOUBLE
#  pragma OPENCL EXTENSION cl_khr_fp64 : enable
#  define SF_REAL double
#endif

#include "device_layout.h"
#include "element.h"

typedef SF_REAL real;

/* The implicit Euler constants of a step: SF_H, SF_MASS_FACTOR, ... */
#include "step_constants.h"

/* Sigma points per work-item in the element kernels: 1 on a GPU (a work-item per element and
 * sigma point), S on a CPU (the host sets it; see element_product.cl). */
#ifndef SF_SIGMA_BLOCK
#  define SF_SIGMA_BLOCK 1
#endif

/* Element chunks of element_product on a CPU (element_product.cl): 0 on a GPU, where each
 * element writes its own outputs for node_product to gather. */
#ifndef SF_ELEMENT_CHUNKS
#  define SF_ELEMENT_CHUNKS 0
#endif

/* The item (element or node) and the first sigma point of the block that work-item `gid`
 * takes in the blocked kernels; 0 for a work-item past the end (the global size is rounded
 * up to whole work-groups). */
static inline int sf_block_item(size_t gid, uint S, uint count, uint* item, uint* first) {
  uint blocks = S / SF_SIGMA_BLOCK;
  if (gid >= (size_t)count * blocks) return 0;
  *item = (uint)(gid / blocks);
  *first = (uint)(gid % blocks) * SF_SIGMA_BLOCK;
  return 1;
}

/* Loads the 15 rest numbers of element e (element.h's grad, vlambda, vmu). */
static inline void sf_load_rest(__global const real* restrict rest, uint e, real grad[12],
                                real* vlambda, real* vmu) {
  __global const real* r = rest + (size_t)e * SF_REST_STRIDE;
  SF_UNROLL
  for (int i = 0; i < 12; ++i) grad[i] = r[i];
  *vlambda = r[12];
  *vmu = r[13];
}

/* Loads element e's four node indices (once per element, for all its sigma points). */
static inline void sf_load_nodes(__global const int* restrict nodes, uint e, int corner_nodes[4]) {
  SF_UNROLL
  for (int c = 0; c < 4; ++c) corner_nodes[c] = nodes[4 * e + c];
}

/* Gathers a per-dof array's values at an element's four corners for sigma point s. */
static inline void sf_gather_corners(__global const real* restrict v, const int corner_nodes[4],
                                     uint s, uint S, real out[12]) {
  SF_UNROLL
  for (int c = 0; c < 4; ++c) {
    size_t base = (size_t)(3 * corner_nodes[c]) * S + s;
    SF_UNROLL
    for (int k = 0; k < 3; ++k) out[3 * c + k] = v[base + (size_t)k * S];
  }
}

/* Loads element e's frame for sigma point s. */
static inline void sf_load_frame(__global const real* restrict frames, uint e, uint s, uint S,
                                 real frame[9]) {
  SF_UNROLL
  for (int i = 0; i < 9; ++i) frame[i] = frames[((size_t)9 * e + i) * S + s];
}

/* Stores 12 corner values of element e for sigma point s. */
static inline void sf_store_corners(__global real* restrict out, uint e, uint s, uint S,
                                    const real values[12]) {
  SF_UNROLL
  for (int i = 0; i < 12; ++i) out[((size_t)12 * e + i) * S + s] = values[i];
}

#endif /* SIGMAFEM_ENSEMBLE_LAYOUT_H */
