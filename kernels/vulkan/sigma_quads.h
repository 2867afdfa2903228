/* sigma_quads.h: the element and node shaders' sigma-quad form (compiled with SF_SIGMA_QUADS),
 * four sigma points a lane: S a multiple of 4, lane (e, q) takes element (or node) e's sigma
 * points 4q .. 4q + 3, and SF_REAL, element.h's and node_rows.h's arithmetic, is a vec4 of
 * them (ensemble_layout.h). On
 * llvmpipe a lane's loads and stores cost by the count, not the width: the element's own data
 * is read once for four sigma points, and each per-sigma value of four comes in one rgba32f
 * texel fetch and goes in one vec4 store, where the scalar form takes four of each (the
 * element product a third faster alone; bench/RESULTS.md, stop 56). The layout is the ensemble's
 * (device_layout.h): [i S + 4 q + j] is quad i Q + q of a per-sigma array, Q = S / 4. */
#ifndef SIGMAFEM_VULKAN_SIGMA_QUADS_H
#define SIGMAFEM_VULKAN_SIGMA_QUADS_H

/* Per-sigma arrays read by quads, SF_QUAD(name, quad): a texel of four floats in the float
 * shaders with texel reads ("_rgba" makes the host view the buffer so: host/vulkan/
 * spirv_bindings.h), else four loads. */
#if defined(SF_TEXEL_READS) && !defined(SF_USE_DOUBLE)
#  define SF_READ_QUADS(slot, name) layout(binding = slot) uniform samplerBuffer name##_rgba;
#  define SF_QUAD(name, i) texelFetch(name##_rgba, int(i))
#else
#  define SF_READ_QUADS(slot, name) SF_READ_REALS(slot, name)
#  define SF_QUAD(name, i) \
    SF_SCALAR4(SF_LOAD(name, 4u * (i)), SF_LOAD(name, 4u * (i) + 1u), SF_LOAD(name, 4u * (i) + 2u), SF_LOAD(name, 4u * (i) + 3u))
#endif
/* A per-sigma array written by quads. */
#define SF_WRITE_QUADS(slot, name) \
  layout(std430, binding = slot) restrict writeonly buffer name##_quads { SF_SCALAR4 name[]; };
/* Sigma constant k of quad q (four loads: the constants' start, SF_STEP_CONSTANTS, is not a
 * multiple of 4). */
#define SF_QUAD_CONSTANT(c, k, q, S)                                                     \
  SF_SCALAR4(SF_SIGMA_CONSTANT(c, k, 4u * (q), S), SF_SIGMA_CONSTANT(c, k, 4u * (q) + 1u, S), \
             SF_SIGMA_CONSTANT(c, k, 4u * (q) + 2u, S), SF_SIGMA_CONSTANT(c, k, 4u * (q) + 3u, S))

/* Element e's rest state (device_layout.h's 16 numbers) for quad q: grad and the Lame terms
 * of its sigma points (SF_SIGMA_LAME's, in its order of operations), and its four nodes. The
 * rest state is read by quads too: 16 numbers an element are four. */
#define SF_QUAD_ELEMENT(rest, nodes, c, e, q, S, grad, sigma_lambda, sigma_mu, corner_nodes) \
  {                                                                                        \
    SF_UNROLL for (uint i_ = 0u; i_ < 3u; ++i_) {                                          \
      SF_SCALAR4 g_ = SF_QUAD(rest, 4u * (e) + i_);                                        \
      SF_UNROLL for (uint j_ = 0u; j_ < 4u; ++j_) grad[4u * i_ + j_] = SF_REAL(g_[j_]);    \
    }                                                                                      \
    SF_SCALAR4 last_ = SF_QUAD(rest, 4u * (e) + 3u);                                       \
    SF_REAL region_ = SF_QUAD_CONSTANT(c, SF_REGION_SCALES + uint(last_[2]), q, S);        \
    sigma_lambda = SF_REAL(last_[0]) * SF_QUAD_CONSTANT(c, SF_LAMBDA_SCALE, q, S) * region_; \
    sigma_mu = SF_REAL(last_[1]) * region_;                                                \
    SF_UNROLL for (uint c_ = 0u; c_ < 4u; ++c_) corner_nodes[c_] = SF_UINT(SF_LOAD(nodes, 4u * (e) + c_)); \
  }
/* Item e's N values of quad q, loaded and stored (device_layout.h's SF_LOAD_FRAME and
 * SF_STORE_CORNERS by quads: [(N e + i) S + s] is quad (N e + i) Q + q). */
#define SF_LOAD_ITEM_QUADS(in, e, N, q, Q, values) \
  SF_UNROLL for (uint i_ = 0u; i_ < (N); ++i_) values[i_] = SF_QUAD(in, ((N) * (e) + i_) * (Q) + (q));
#define SF_STORE_ITEM_QUADS(out, e, N, q, Q, values) \
  SF_UNROLL for (uint i_ = 0u; i_ < (N); ++i_) out[((N) * (e) + i_) * (Q) + (q)] = values[i_];
/* A per-dof array's quads at an element's four corners. */
#define SF_GATHER_CORNER_QUADS(v, corner_nodes, q, Q, out)                            \
  SF_UNROLL for (uint c_ = 0u; c_ < 4u; ++c_)                                         \
    SF_UNROLL for (uint k_ = 0u; k_ < 3u; ++k_)                                       \
      out[3u * c_ + k_] = SF_QUAD(v, (3u * corner_nodes[c_] + k_) * (Q) + (q));

/* node_rows.h's SF_CORNER_SUMS by quads: the three axes' sums of a per-corner output over node
 * n's incident corners, in the incidence order. */
#define SF_CORNER_SUM_QUADS(values, incidence_offsets, incidence, n, q, Q, sum)       \
  {                                                                                  \
    sum[0] = SF_LIT(0);                                                              \
    sum[1] = SF_LIT(0);                                                              \
    sum[2] = SF_LIT(0);                                                              \
    int end_ = SF_LOAD(incidence_offsets, (n) + 1u);                                 \
    for (int i_ = SF_LOAD(incidence_offsets, n); i_ < end_; ++i_) {                  \
      uint base_ = 3u * uint(SF_LOAD(incidence, i_)) * (Q) + (q);                    \
      sum[0] += SF_QUAD(values, base_);                                              \
      sum[1] += SF_QUAD(values, base_ + (Q));                                        \
      sum[2] += SF_QUAD(values, base_ + 2u * (Q));                                   \
    }                                                                                \
  }
/* node_rows.h's SF_NODE_SPRING by quads (ligament_k read by quads: [l S + s]). */
#define SF_NODE_SPRING_QUADS(ligament_offsets, ligament_of_node, ligament_k, control_k, n, q, Q, spring) \
  {                                                                                  \
    spring = SF_REAL(SF_LOAD(control_k, n));                                         \
    int end_ = SF_LOAD(ligament_offsets, (n) + 1u);                                  \
    for (int i_ = SF_LOAD(ligament_offsets, n); i_ < end_; ++i_)                     \
      spring += SF_QUAD(ligament_k, uint(SF_LOAD(ligament_of_node, i_)) * (Q) + (q)); \
  }

#endif /* SIGMAFEM_VULKAN_SIGMA_QUADS_H */
