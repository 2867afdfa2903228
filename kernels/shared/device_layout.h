/* device_layout.h: how a device ensemble lays out its buffers and what each kernel takes, read
 * by the OpenCL kernels, the Vulkan shaders and the host (host/ensemble/device_buffers.cpp
 * builds its table of each kernel's buffers from the slots below; the shaders bind by them).
 *
 * Every per-sigma array has the sigma index innermost, so that neighbouring work-items
 * (neighbouring sigma points) read neighbouring addresses:
 *   per-dof     x[(3 * node + axis) * S + s]
 *   per-element frames[(9 * e + i) * S + s],  corner outputs [(12 * e + i) * S + s]
 * (Vulkan keeps a frame's first two rows only: frames[(SF_FRAME_TWO_ROWS * e + i) * S + s].)
 * Shared data (rest shape, element rest state, mass) is stored once for all sigma points.
 * Work-items of the element and node kernels: gid = item * S + s. */
#ifndef SIGMAFEM_DEVICE_LAYOUT_H
#define SIGMAFEM_DEVICE_LAYOUT_H

#include "dialect.h"

/* The element rest state, 16 numbers per element: grad[12], vlambda, vmu, the element's region
 * slot (step_constants.h, SF_REGION_SCALES; a small integer held as a real), one unused. */
#define SF_REST_STRIDE 16u
#define SF_REST_REGION_SLOT 14u

/* An element frame's numbers where a back end keeps its first two rows only (Vulkan,
 * kernels/vulkan/ensemble_layout.h's SF_FRAME_ROWS_KEPT; the third is their cross product). */
#define SF_FRAME_TWO_ROWS 6u

/* The index helpers of the element kernels, over the buffers of the layout above. */
/* Element e's rest state (element.h's grad[12], vlambda, vmu) and its four nodes (uint). */
#define SF_LOAD_ELEMENT(rest, nodes, e, grad, vlambda, vmu, corner_nodes)            \
  SF_UNROLL for (uint i_ = 0u; i_ < 12u; ++i_) grad[i_] =                            \
      SF_LOAD(rest, SF_INDEX(e) * SF_REST_STRIDE + i_);                                \
  vlambda = SF_LOAD(rest, SF_INDEX(e) * SF_REST_STRIDE + 12u);                         \
  vmu = SF_LOAD(rest, SF_INDEX(e) * SF_REST_STRIDE + 13u);                             \
  SF_UNROLL for (uint c_ = 0u; c_ < 4u; ++c_) corner_nodes[c_] = SF_UINT(SF_LOAD(nodes, 4u * (e) + c_));
/* Element e's region slot (step_constants.h, SF_REGION_SCALES). */
#define SF_REGION_SLOT(rest, e) SF_UINT(SF_LOAD(rest, SF_INDEX(e) * SF_REST_STRIDE + SF_REST_REGION_SLOT))
/* Sigma point s's Lame terms of element e from its rest state's vlambda and vmu: lambda times
 * the sigma point's lambda_scale, both times its scale of the element's region slot. */
#define SF_SIGMA_LAME(rest, c, e, s, S, vlambda, vmu, sigma_lambda, sigma_mu)                 \
  {                                                                                           \
    SF_REAL region_ = SF_SIGMA_CONSTANT(c, SF_REGION_SCALES + SF_REGION_SLOT(rest, e), s, S); \
    sigma_lambda = vlambda * SF_SIGMA_CONSTANT(c, SF_LAMBDA_SCALE, s, S) * region_;           \
    sigma_mu = vmu * region_;                                                                 \
  }
/* A per-dof buffer's values at an element's four corners for sigma point s. */
#define SF_GATHER_CORNERS(v, corner_nodes, s, S, out)                                \
  SF_UNROLL for (uint c_ = 0u; c_ < 4u; ++c_)                                          \
    SF_UNROLL for (uint k_ = 0u; k_ < 3u; ++k_)                                        \
      out[3u * c_ + k_] = SF_LOAD(v, SF_INDEX(3u * corner_nodes[c_] + k_) * (S) + (s));
/* Element e's frame for sigma point s, loaded and stored. */
#define SF_LOAD_FRAME(frames, e, s, S, frame) \
  SF_UNROLL for (uint i_ = 0u; i_ < 9u; ++i_) frame[i_] = SF_LOAD(frames, (SF_INDEX(9u) * (e) + i_) * (S) + (s));
#define SF_STORE_FRAME(frames, e, s, S, frame) \
  SF_UNROLL for (uint i_ = 0u; i_ < 9u; ++i_) frames[(SF_INDEX(9u) * (e) + i_) * (S) + (s)] = frame[i_];
/* 12 corner values of element e for sigma point s, stored. */
#define SF_STORE_CORNERS(out, e, s, S, values) \
  SF_UNROLL for (uint i_ = 0u; i_ < 12u; ++i_) out[(SF_INDEX(12u) * (e) + i_) * (S) + (s)] = values[i_];

/* Work-items per group of the element and node kernels. */
#define SF_ITEMS_PER_GROUP 64

/* The scalars every kernel is given (Vulkan: the 16 bytes of push constants, SfPush; OpenCL:
 * the leading scalar arguments, those a kernel needs): the sigma points, the kernel's item
 * count (elements, nodes, rows or observed points), the CG iteration cap and the filter's
 * parameter count (recenter). UINT(name), INT(name) declare one each. */
#define SF_PUSH_CONSTANTS(UINT, INT) UINT(S) UINT(count) INT(max_iterations) UINT(p)

/* Buffer slots: a buffer's position among a kernel's buffer arguments (OpenCL: after its
 * scalars) and its binding (Vulkan, descriptor set 0). */
/* element_rhs */
#define SF_ELEMENT_RHS_ELEMENT_NODES 0
#define SF_ELEMENT_RHS_ELEMENT_REST 1
#define SF_ELEMENT_RHS_FRAMES 2
#define SF_ELEMENT_RHS_X 3
#define SF_ELEMENT_RHS_V 4
#define SF_ELEMENT_RHS_CONSTANTS 5
#define SF_ELEMENT_RHS_ELEMENT_OUT 6
#define SF_ELEMENT_RHS_ELEMENT_DIAGONAL 7
/* element_product (d and active: dv or d, all_active or active, by the call) */
#define SF_ELEMENT_PRODUCT_ELEMENT_NODES 0
#define SF_ELEMENT_PRODUCT_ELEMENT_REST 1
#define SF_ELEMENT_PRODUCT_FRAMES 2
#define SF_ELEMENT_PRODUCT_D 3
#define SF_ELEMENT_PRODUCT_ACTIVE 4
#define SF_ELEMENT_PRODUCT_ELEMENT_OUT 5
#define SF_ELEMENT_PRODUCT_CONSTANTS 6
/* the node kernels (node_rhs, node_product, Vulkan's cg_start): what a node row reads
 * (node_rows.h), then each kernel's own */
#define SF_NODE_CONSTANTS 0
#define SF_NODE_INCIDENCE_OFFSETS 1
#define SF_NODE_INCIDENCE 2
#define SF_NODE_LIGAMENT_OFFSETS 3
#define SF_NODE_LIGAMENT_OF_NODE 4
#define SF_NODE_LIGAMENT_K 5
#define SF_NODE_CONTROL_K 6
#define SF_NODE_MASS 7
#define SF_NODE_RHS_REST_POSITIONS 8
#define SF_NODE_RHS_X 9
#define SF_NODE_RHS_V 10
#define SF_NODE_RHS_ELEMENT_OUT 11
#define SF_NODE_RHS_ELEMENT_DIAGONAL 12
#define SF_NODE_RHS_RHS 13
#define SF_NODE_RHS_INVERSE_DIAGONAL 14
#define SF_NODE_PRODUCT_D 8
#define SF_NODE_PRODUCT_ELEMENT_OUT 9
#define SF_NODE_PRODUCT_Q 10
/* state_update */
#define SF_STATE_UPDATE_CONSTANTS 0
#define SF_STATE_UPDATE_BB 1
#define SF_STATE_UPDATE_DV 2
#define SF_STATE_UPDATE_X 3
#define SF_STATE_UPDATE_V 4
/* observation_gather */
#define SF_OBSERVATION_GATHER_OBSERVED_NODES 0
#define SF_OBSERVATION_GATHER_OBSERVED_WEIGHTS 1
#define SF_OBSERVATION_GATHER_X 2
#define SF_OBSERVATION_GATHER_OBSERVATIONS 3
/* recenter */
#define SF_RECENTER_RECENTER_SCALARS 0
#define SF_RECENTER_DIRECTIONS 1
#define SF_RECENTER_WEIGHTS 2
#define SF_RECENTER_X 3
#define SF_RECENTER_V 4

/* Vulkan's CG shaders (conjugate_gradient.comp; OpenCL's CG kernels take lists of their own,
 * host/opencl/opencl_ensemble.cpp). The start's three shaders: the node rows' slots, then */
#define SF_CG_START_ELEMENT_OUT 8
#define SF_CG_START_RHS 9
#define SF_CG_START_INVERSE_DIAGONAL 10
#define SF_CG_START_DV 11
#define SF_CG_START_R 12
#define SF_CG_START_Z 13
#define SF_CG_START_D 14
#define SF_CG_START_BB 15
#define SF_CG_START_RR 16
#define SF_CG_START_RZ 17
#define SF_CG_START_ACTIVE 18
#define SF_CG_START_CONVERGED 19
#define SF_CG_START_ITERATIONS 20
#define SF_CG_START_PARTIAL 21
#define SF_CG_START_OWN_ACTIVE 22
#define SF_CG_START_OWN_ITERATIONS 23
#define SF_CG_START_OWN_RZ 24
/* the iteration's four (x of CG is the velocity change dv): */
#define SF_CG_ITERATION_CONSTANTS 0
#define SF_CG_ITERATION_INVERSE_DIAGONAL 1
#define SF_CG_ITERATION_DV 2
#define SF_CG_ITERATION_R 3
#define SF_CG_ITERATION_Z 4
#define SF_CG_ITERATION_D 5
#define SF_CG_ITERATION_Q 6
#define SF_CG_ITERATION_BB 7
#define SF_CG_ITERATION_RR 8
#define SF_CG_ITERATION_RZ 9
#define SF_CG_ITERATION_ACTIVE 10
#define SF_CG_ITERATION_CONVERGED 11
#define SF_CG_ITERATION_ITERATIONS 12
#define SF_CG_ITERATION_PARTIAL 13
#define SF_CG_ITERATION_OWN_ACTIVE 14
#define SF_CG_ITERATION_OWN_ITERATIONS 15
#define SF_CG_ITERATION_OWN_RZ 16
/* and what cg_node_iteration reads to form q = A d itself (node_product's rows) */
#define SF_CG_ITERATION_INCIDENCE_OFFSETS 17
#define SF_CG_ITERATION_INCIDENCE 18
#define SF_CG_ITERATION_LIGAMENT_OFFSETS 19
#define SF_CG_ITERATION_LIGAMENT_OF_NODE 20
#define SF_CG_ITERATION_LIGAMENT_K 21
#define SF_CG_ITERATION_CONTROL_K 22
#define SF_CG_ITERATION_MASS 23
#define SF_CG_ITERATION_ELEMENT_OUT 24
/* Vulkan's factor_solve (z = M^-1 r with a sparse Cholesky factor in 4 x 4 blocks;
 * host/vulkan/vulkan_factor_solve.h, host/reference/factor_blocks.h): the blocks by rows (for
 * L y = P r: each block row's start, each block's column panel) and by columns (for L^T w = y),
 * each slot's original row, CG's r, z and active flags, the factor's correction for each sigma
 * point's springs (host/reference/spring_correction.h): [m, reached slots u, the slots], V
 * there by rows and each sigma point's m x m H; the panels' triangles, the blocks' values by
 * rows and by columns, and the work vector y (bound twice: read as texels, written as a storage
 * buffer, where llvmpipe stores a texel several times slower: factor_solve.comp); CG's d and
 * r.z, which it finishes (push constant max_iterations: SF_FACTOR_FINISH_*). */
#define SF_FACTOR_SOLVE_FORWARD_STARTS 0
#define SF_FACTOR_SOLVE_FORWARD_PANEL 1
#define SF_FACTOR_SOLVE_BACKWARD_STARTS 2
#define SF_FACTOR_SOLVE_BACKWARD_PANEL 3
#define SF_FACTOR_SOLVE_SLOT_ROWS 4
#define SF_FACTOR_SOLVE_R 5
#define SF_FACTOR_SOLVE_Z 6
#define SF_FACTOR_SOLVE_ACTIVE 7
#define SF_FACTOR_SOLVE_SPRING_AT 8
#define SF_FACTOR_SOLVE_SPRING_SOLVES 9
#define SF_FACTOR_SOLVE_SPRING_COUPLING 10
#define SF_FACTOR_SOLVE_TRIANGLES 11
#define SF_FACTOR_SOLVE_FORWARD_BLOCKS 12
#define SF_FACTOR_SOLVE_BACKWARD_BLOCKS 13
#define SF_FACTOR_SOLVE_WORK 14
#define SF_FACTOR_SOLVE_WORK_STORES 15
#define SF_FACTOR_SOLVE_D 16
#define SF_FACTOR_SOLVE_RZ 17
#define SF_FACTOR_SOLVE_BINDINGS 18
/* What factor_solve does after z = M^-1 r: nothing (z alone), CG's start (r.z, d = z) or an
 * iteration's direction (r.z, beta = r.z / the last r.z, d = z + beta d). */
#define SF_FACTOR_FINISH_NONE 0u
#define SF_FACTOR_FINISH_START 1u
#define SF_FACTOR_FINISH_DIRECTION 2u
/* y's quads a step of that d takes (a step's loop turns: factor_solve.comp) */
#define SF_FACTOR_FINISH_QUADS 64u
/* Vulkan's multigrid shaders (mg_smooth, mg_residual, mg_product: the V-cycle of
 * host/reference/nested_multigrid.h; host/vulkan/vulkan_multigrid.h): a level's matrix in CSR,
 * its diagonal, its Chebyshev steps, the finest level's shifts, the input vector (b, or x of a
 * product), x and p in, the output (x, r or y) and p out. Push constants: count the rows,
 * max_iterations the step k, p the flags SF_MG_FROM_ZERO | SF_MG_SHIFTED | SF_MG_ACCUMULATE. */
#define SF_MG_ROW_START 0
#define SF_MG_COLUMNS 1
#define SF_MG_VALUES 2
#define SF_MG_DIAGONAL 3
#define SF_MG_STEPS 4
#define SF_MG_SHIFT 5
#define SF_MG_IN 6
#define SF_MG_X 7
#define SF_MG_P 8
#define SF_MG_OUT 9
#define SF_MG_P_OUT 10
#define SF_MG_BINDINGS 11
#define SF_MG_FROM_ZERO 1u
#define SF_MG_SHIFTED 2u
#define SF_MG_ACCUMULATE 4u

#endif /* SIGMAFEM_DEVICE_LAYOUT_H */
