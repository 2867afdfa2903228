/* element_product: y_e = R K_e R^T d_e for every element and sigma point, the cost of every
 * CG iteration (host: element_product in host/reference/corotational.h), K_e with the sigma
 * point's scale of Lame's lambda (SF_LAMBDA_SCALE, step_constants.h). No atomics, and the
 * sums come out in the same order every run, in one of two ways (the host chooses):
 *
 * Element outputs (a GPU): a work-item takes one element and one sigma point and writes the
 * element's own 12 outputs; node_product (node_assembly.cl) gathers them at each node.
 *
 * Chunks (a CPU, SF_ELEMENT_CHUNKS > 0): a work-item takes a contiguous chunk of the elements,
 * in order, for all S sigma points (SF_SIGMA_BLOCK = S: the loop over them, on contiguous
 * data, is vectorised), and adds each product straight into its own copy of the 3N x S
 * result; node_product sums the copies, in chunk order. The copies are small enough to stay
 * in cache, where the element outputs (12 E S numbers, 29 MB at 38k tetrahedra and S = 16)
 * went through memory twice per iteration. */
#include "element_chunk.h"

__kernel void element_product(uint S, uint element_count, uint node_count,
                              __global const int* restrict nodes,
                              __global const real* restrict rest, __global const real* restrict frames,
                              __global const real* restrict d, __global const uint* restrict active,
                              __global real* restrict element_out, __global const real* restrict c) {
#if SF_ELEMENT_CHUNKS > 0
  uint chunk = (uint)get_global_id(0);
  if (chunk >= SF_ELEMENT_CHUNKS) return;
  sf_element_chunk_products(sf_chunk_start(chunk, element_count),
                            sf_chunk_start(chunk + 1, element_count), 0,
                            SF_SIGMA_BLOCK, S, S, node_count, nodes, rest, frames, c, d,
                            element_out + chunk * ((size_t)3 * node_count * S));
#else
  uint e;
  uint first;
  if (!sf_block_item(get_global_id(0), S, element_count, &e, &first)) return;
  real grad[12];
  real vlambda;
  real vmu;
  uint corner_nodes[4];
  SF_LOAD_ELEMENT(rest, nodes, e, grad, vlambda, vmu, corner_nodes)
  for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) {
    uint s = first + b;
#  if SF_SIGMA_BLOCK == 1
    if (!active[s]) return; /* this sigma point's CG is done */
#  endif
    real sigma_lambda;
    real sigma_mu;
    SF_SIGMA_LAME(rest, c, e, s, S, vlambda, vmu, sigma_lambda, sigma_mu)
    real frame[9];
    real corner[12];
    real product[12];
    SF_LOAD_FRAME(frames, e, s, S, frame)
    SF_GATHER_CORNERS(d, corner_nodes, s, S, corner)
    sf_element_product(frame, grad, sigma_lambda, sigma_mu, corner, product);
    SF_STORE_CORNERS(element_out, e, s, S, product)
  }
#endif
}
