/* element_chunk.h: K d over a contiguous chunk of elements for the sigma points first ..
 * first + count - 1, added into one copy of K d (element_product.cl's form on a CPU, and
 * cg_solve's). The elements are taken in order and the copy belongs to the caller alone: no
 * atomics, the same bits every run. d and the copy are [row * stride + i] for the block's
 * i-th sigma point (stride S with first = 0: the ensemble's layout; cg_solve's blocks pass
 * their own vectors, stride count); the frames and step constants are the ensemble's.
 * count is a constant after inlining: the loops over the sigma points, on contiguous data,
 * are vectorised. */
#ifndef SIGMAFEM_ELEMENT_CHUNK_H
#define SIGMAFEM_ELEMENT_CHUNK_H

#include "ensemble_layout.h"

static inline __attribute__((always_inline)) void sf_element_chunk_products(
    uint begin, uint end, uint first, uint count, uint S, uint stride, uint node_count,
    __global const int* restrict nodes, __global const real* restrict rest,
    __global const real* restrict frames, __global const real* restrict c,
    __global const real* restrict d, __global real* restrict copy) {
  const size_t copy_size = (size_t)3 * node_count * stride;
  for (size_t i = 0; i < copy_size; ++i) copy[i] = (real)0;
  real lambda_scale[SF_SIGMA_BLOCK]; /* read once, not once per element */
  for (uint s = 0; s < count; ++s) lambda_scale[s] = SF_SIGMA_CONSTANT(c, SF_LAMBDA_SCALE, first + s, S);
  for (uint e = begin; e < end; ++e) {
    real grad[12];
    real vlambda;
    real vmu;
    uint corner_nodes[4];
    SF_LOAD_ELEMENT(rest, nodes, e, grad, vlambda, vmu, corner_nodes)
    const uint region = SF_REGION_SCALES + SF_REGION_SLOT(rest, e);
    /* The products of all sigma points first, then the additions, each a loop over the
     * sigma points on contiguous data: the compiler vectorises both (with the additions in
     * the first loop it could not, not knowing that the corners' nodes differ). */
    real products[12][SF_SIGMA_BLOCK];
    for (uint s = 0; s < count; ++s) {
      real frame[9];
      real corner[12];
      real product[12];
      SF_LOAD_FRAME(frames, e, first + s, S, frame)
      SF_GATHER_CORNERS(d, corner_nodes, s, stride, corner)
      const real region_scale = SF_SIGMA_CONSTANT(c, region, first + s, S);
      sf_element_product(frame, grad, vlambda * lambda_scale[s] * region_scale, vmu * region_scale, corner,
                         product);
      SF_UNROLL
      for (int i = 0; i < 12; ++i) products[i][s] = product[i];
    }
    SF_UNROLL
    for (int i = 0; i < 12; ++i) {
      __global real* restrict row = copy + (size_t)(3 * corner_nodes[i / 3] + i % 3) * stride;
      for (uint s = 0; s < count; ++s) row[s] += products[i][s];
    }
  }
}

#endif /* SIGMAFEM_ELEMENT_CHUNK_H */
