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

/* 1: CG is preconditioned by a sparse Cholesky factor (conjugate_gradient.cl, the CPU form),
 * and the Jacobi diagonal is neither made (element_rhs, node_rhs) nor read. */
#ifndef SF_FACTOR
#  define SF_FACTOR 0
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

/* The first element of chunk `chunk` of SF_ELEMENT_CHUNKS (chunk SF_ELEMENT_CHUNKS: the end):
 * the CPU form's element kernels (element_product.cl, element_rhs.cl) take contiguous chunks. */
#if SF_ELEMENT_CHUNKS > 0
static inline uint sf_chunk_start(uint chunk, uint element_count) {
  return (uint)((ulong)element_count * chunk / SF_ELEMENT_CHUNKS);
}
#endif

#endif /* SIGMAFEM_ENSEMBLE_LAYOUT_H */
