/* factor_solve: z = M^-1 r for CG with one sparse Cholesky factor shared by the sigma points
 * (M = P^T L L^T P, made on the host from the representative's system:
 * host/reference/factorised_preconditioner.h; host: host/vulkan/vulkan_factor_solve.cpp;
 * OpenCL's sf_block_factor_solve in conjugate_gradient.cl does the same on PoCL).
 *
 * A lane per sigma point (work-group g holds sigma points g G .. g G + G - 1, G the group
 * size, specialization constant 0), or H lanes (factor_solve_split, below): the substitutions are sequential along L's rows, while
 * the sigma points are independent, and L's entries are read once for the group at the same
 * address in every lane. L comes in dense 4 x 4 blocks (host/reference/factor_blocks.h): the
 * vector y by slots, a vec4 per panel of 4 rows, and a block's 16 entries in 4 vec4 reads,
 * so that a substitution turns once per block where it turned once per entry (the liver's
 * factor: 2334 blocks for 26 088 entries; bench/RESULTS.md, stop 55). Both substitutions read,
 * never scatter: L y = P r by block rows (y_q = T_q^-1 ((P r)_q - sum_p<q L_qp y_p)) and
 * L^T w = y by block columns (w_p = T_p^-T (y_p - sum_q>p L_qp^T w_q)), each w_p also stored
 * as z at its original rows (unless SF_FACTOR_STORES_Z is 0, below). Between them, the
 * correction for the sigma point's own springs (SpringCorrection,
 * host/reference/spring_correction.h; OpenCL's SF_SPRING_ROWS): y -= V H_s V^T y at the slots
 * V reaches, with V^T y and H_s V^T y kept in slots 4 P .. 4 P + 2M - 1.
 *
 * llvmpipe ends every loop of an invocation, silently, once its loops together have turned
 * 65535 times (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS; bench/RESULTS.md, stop 52). So the
 * solve is a sequence of steps, each a short loop, and one dispatch does a range of them, cut
 * by the host to a bound of loop turns (push constants: count = the first step, p = one past
 * the last; S the sigma points). The steps, with P panels and m spring rows reaching u slots
 * (V by rows, each padded with zeros to M = m rounded up to 4, and read 4 at a time):
 *   [0, P)                          the forward block rows
 *   [P, P + M/4)                    V^T y, 4 of its m at a time, a sum over the u slots each
 *   [P + M/4, P + M/4 + m)          H_s V^T y, a sum over m each
 *   [P + M/4 + m, ... + u)          y -= V H_s V^T y at one reached slot each, M/4 turns
 *   [P + M/4 + m + u, 2P + ... + u) the backward block columns, from the last
 *   [2P + M/4 + m + u, ...)          CG's d (below), SF_FACTOR_FINISH_QUADS of y's quads each.
 * An inactive sigma point (CG done) is left alone.
 *
 * CG's own step after z (push constant max_iterations, SF_FACTOR_FINISH_*; none for z alone):
 * r.z is summed as the backward substitution stores each panel's z (kept in y's quad
 * P + 2 M / 4 between dispatches, with beta = r.z / the last r.z after the last), r.z stored,
 * and the last steps form d = z (the start) or d = z + beta d (an iteration) from y's slots,
 * which hold z: the lanes own their sigma points, so that this needs no dispatch of its own
 * (what conjugate_gradient.comp's cg_factor_start and cg_factor_direction did until stop 59).
 *
 * In float32, y and the blocks are rgba32f storage texel buffers and V an rgba32f uniform
 * texel buffer: llvmpipe loads a storage buffer at lane-varying addresses one lane at a time,
 * a texel in one gather (bench/RESULTS.md, stop 53); y is written through a storage buffer
 * bound to the same memory (SF_FACTOR_SOLVE_WORK_STORES), where llvmpipe stores a vec4 about
 * 6x faster than a texel (bench/RESULTS.md, stop 57). In float64 (no 64-bit texel format)
 * storage buffers. */
#version 450
#extension GL_GOOGLE_include_directive : require
#if defined(SF_SPLIT_BLOCK_ROWS) || defined(SF_SHARED_BLOCKS)
#  extension GL_KHR_shader_subgroup_shuffle : require
#endif
#include "ensemble_layout.h"

layout(local_size_x_id = 0) in;
/* P, the panels of L (host/reference/factor_blocks.h), set at pipeline creation. */
layout(constant_id = 1) const uint SF_FACTOR_PANELS = 1u;
/* Whether z is stored (1), or only CG's d and r.z from it (0: the ensemble's solves, which
 * always finish CG's step; llvmpipe loops over the lanes for every store it compiles, taken or
 * not: left out, the 4768 liver's solve at S = 16 took 1098-1236 us against 1202-1410;
 * bench/RESULTS.md, stop 60). */
layout(constant_id = 2) const uint SF_FACTOR_STORES_Z = 1u;

SF_READ_INTS(SF_FACTOR_SOLVE_FORWARD_STARTS, forward_starts)
SF_READ_INTS(SF_FACTOR_SOLVE_FORWARD_PANEL, forward_panel)
SF_READ_INTS(SF_FACTOR_SOLVE_BACKWARD_STARTS, backward_starts)
SF_READ_INTS(SF_FACTOR_SOLVE_BACKWARD_PANEL, backward_panel)
SF_READ_INTS(SF_FACTOR_SOLVE_SLOT_ROWS, slot_rows)
SF_READ_REALS(SF_FACTOR_SOLVE_R, r)
layout(std430, binding = SF_FACTOR_SOLVE_Z) restrict writeonly buffer Z { real z[]; };
SF_READ_UINTS(SF_FACTOR_SOLVE_ACTIVE, active_flags)
SF_READ_INTS(SF_FACTOR_SOLVE_SPRING_AT, spring_at)
SF_READ_REALS(SF_FACTOR_SOLVE_SPRING_COUPLING, spring_coupling)
layout(std430, binding = SF_FACTOR_SOLVE_D) restrict buffer D { real d[]; };
layout(std430, binding = SF_FACTOR_SOLVE_RZ) restrict buffer RZ { real rz[]; };
#if defined(SF_USE_DOUBLE)
#  define real4 dvec4
layout(std430, binding = SF_FACTOR_SOLVE_TRIANGLES) restrict readonly buffer Triangles { dvec4 triangles[]; };
layout(std430, binding = SF_FACTOR_SOLVE_FORWARD_BLOCKS) restrict readonly buffer Forward { dvec4 forward_blocks[]; };
layout(std430, binding = SF_FACTOR_SOLVE_BACKWARD_BLOCKS) restrict readonly buffer Backward { dvec4 backward_blocks[]; };
layout(std430, binding = SF_FACTOR_SOLVE_WORK) restrict buffer Work { dvec4 y[]; };   /* _STORES unused */
layout(std430, binding = SF_FACTOR_SOLVE_SPRING_SOLVES) restrict readonly buffer SpringSolves { dvec4 spring_solves[]; };
#  define SF_V4(i) spring_solves[i]
#  define SF_COLUMN(blocks, i) blocks[i]
#  define SF_Y4(t) y[t]
#  define SF_SET_Y4(t, value) if (writes) y[t] = (value)
#else
#  define real4 vec4
layout(binding = SF_FACTOR_SOLVE_TRIANGLES, rgba32f) uniform restrict readonly imageBuffer triangles;
layout(binding = SF_FACTOR_SOLVE_FORWARD_BLOCKS, rgba32f) uniform restrict readonly imageBuffer forward_blocks;
layout(binding = SF_FACTOR_SOLVE_BACKWARD_BLOCKS, rgba32f) uniform restrict readonly imageBuffer backward_blocks;
/* y read as texels and written as vec4s, one memory through two bindings (not restrict: they alias). */
layout(binding = SF_FACTOR_SOLVE_WORK, rgba32f) uniform readonly imageBuffer y;
layout(std430, binding = SF_FACTOR_SOLVE_WORK_STORES) writeonly buffer WorkStores { vec4 y_stores[]; };
/* V, 4 of a row a texel ("_rgba": host/vulkan/spirv_bindings.h). */
layout(binding = SF_FACTOR_SOLVE_SPRING_SOLVES) uniform samplerBuffer spring_solves_rgba;
#  define SF_V4(i) texelFetch(spring_solves_rgba, int(i))
#  define SF_COLUMN(blocks, i) imageLoad(blocks, int(i))
#  define SF_Y4(t) imageLoad(y, int(t))
#  define SF_SET_Y4(t, value) if (writes) y_stores[t] = (value)
#endif

uint S, s;
/* The split (SF_SPLIT_BLOCK_ROWS, factor_solve_split: with S of at most 4, H = G / S lanes a
 * sigma point, h this lane's part; bench/RESULTS.md, stop 56): a block row's (or column's)
 * blocks, and the terms of each of the correction's sums, are shared out, lane h taking every
 * H-th from its h-th, so that each lane turns a H-th as often; the H partial sums
 * are added by subgroup shuffles (the group is one subgroup: the host's condition), in lane
 * order, the same total in each of the H lanes. Each lane keeps its own copy of y (H copies,
 * [(t H + h) S + s]), which it alone reads and writes: the lanes share nothing but the
 * shuffles. Where the sigma points fill the lanes already, one lane a sigma point (H = 1). */
uint H, h;
/* The shared block reads (SF_SHARED_BLOCKS, factor_solve_shared: a lane a sigma point, S >= 5,
 * a group of 8 lanes in one subgroup; bench/RESULTS.md, stop 57): every lane needs the same
 * blocks, so the 8 lanes read a chunk of 8 blocks' 32 texels together, 4 each, and each block's
 * 4 columns reach every lane by subgroup shuffles from constant lanes (which llvmpipe does in
 * registers), where each lane read all 32 alone. All 8 lanes take part, those past S or whose
 * sigma point is done included (shuffles read only active lanes), and only the others write
 * (`writes`). */
#if defined(SF_SHARED_BLOCKS)
uint lane;
bool writes;
#else
const bool writes = true;   /* every lane that runs writes: no test at the stores */
#endif

/* The quad t (4 slots) of y: this lane's copy for its sigma point. */
uint y_quad(uint t) { return (t * H + h) * S + s; }
/* The sum of the H lanes' partial sums of this lane's sigma point, in lane order. */
real4 add_parts(real4 part) {
#if defined(SF_SPLIT_BLOCK_ROWS)   /* lanes [j S + s], j < H, hold sigma point s's parts */
  real4 total = real4(0);
  for (uint j = 0u; j < 8u; ++j)   /* constant bounds: unrolled, no loop turns */
    if (j < H) total += subgroupShuffle(part, j * S + s);
  return total;
#else
  return part;
#endif
}

real add_parts(real part) { return add_parts(real4(part, 0, 0, 0)).x; }

/* One slot of y, and one set, for this lane's sigma point. */
real y_at(uint slot) { return SF_Y4(y_quad(slot >> 2u))[slot & 3u]; }
void set_y_at(uint slot, real value) {
  uint t = y_quad(slot >> 2u);
  real4 four = SF_Y4(t);
  four[slot & 3u] = value;
  SF_SET_Y4(t, four);
}

#if defined(SF_SHARED_BLOCKS)
/* Blocks k0 .. k0 + 7 of a row (those past its `end` repeat its last, unused): lane l reads
 * the l-th block's panel and texels l, l + 8, l + 16 and l + 24 of the chunk's 32 (f0..f3). */
#  define SF_READ_CHUNK(panels, blocks)                                                        \
  int panel = SF_LOAD(panels, uint(min(k0 + int(lane), end - 1)));                             \
  uint at_ = 4u * uint(k0) + lane, last_ = 4u * uint(end) - 1u;                               \
  real4 f0 = SF_COLUMN(blocks, min(at_, last_)), f1 = SF_COLUMN(blocks, min(at_ + 8u, last_)); \
  real4 f2 = SF_COLUMN(blocks, min(at_ + 16u, last_)), f3 = SF_COLUMN(blocks, min(at_ + 24u, last_));
/* BLOCK(j, f, l) for the chunk's 8 blocks: block j's 4 columns are lanes l .. l + 3 of f. */
#  define SF_EACH_CHUNK_BLOCK(BLOCK)                                                           \
  BLOCK(0, f0, 0u) BLOCK(1, f0, 4u) BLOCK(2, f1, 0u) BLOCK(3, f1, 4u)                          \
  BLOCK(4, f2, 0u) BLOCK(5, f2, 4u) BLOCK(6, f3, 0u) BLOCK(7, f3, 4u)
#endif

void main() {
  S = sf_push.S;
#if defined(SF_SPLIT_BLOCK_ROWS)   /* one group of H S lanes */
  H = gl_WorkGroupSize.x / S;
  s = gl_LocalInvocationID.x % S;
  h = gl_LocalInvocationID.x / S;
  if (h >= H || SF_LOAD(active_flags, s) == 0u) return;   /* all H lanes of a sigma point alike */
#elif defined(SF_SHARED_BLOCKS)   /* groups of 8, every lane to the end */
  H = 1u;
  h = 0u;
  lane = gl_SubgroupInvocationID;
  s = gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  writes = s < S && SF_LOAD(active_flags, min(s, S - 1u)) != 0u;
  s = min(s, S - 1u);
  uint any_writes = 0u;
  for (uint l = 0u; l < 8u; ++l) any_writes |= subgroupShuffle(writes ? 1u : 0u, l);   /* unrolled */
  if (any_writes == 0u) return;   /* the whole group: no shuffle is left without its lanes */
#else
  H = 1u;
  h = 0u;
  s = gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (s >= S || SF_LOAD(active_flags, s) == 0u) return;
#endif
  uint P = SF_FACTOR_PANELS;
  uint finish = uint(sf_push.max_iterations);
  uint m = uint(SF_LOAD(spring_at, 0)), reached = uint(SF_LOAD(spring_at, 1));
  uint quads = (m + 3u) / 4u;   /* M / 4 */
  uint projected = P, coupled = P + quads, updated = P + quads + m, backward = P + quads + m + reached;
  uint sums = 4u * P;   /* the slot of (V^T y)_0, quad P; (H V^T y)_0 at slot 4 P + M, quad P + M/4 */
  uint first = sf_push.count, last = sf_push.p;
  for (uint q = first; q < min(last, projected); ++q) { /* L y = P r: block row q */
    real4 b;
    for (uint c = 0u; c < 4u; ++c) {   /* constant bounds: unrolled, no loop turns */
      int row = SF_LOAD(slot_rows, 4u * q + c);
      b[c] = row < 0 || h > 0u ? real(0) : SF_LOAD(r, uint(row) * S + s);   /* P r once */
    }
    int end = SF_LOAD(forward_starts, q + 1u);   /* read once, not at every turn's test */
#if defined(SF_SHARED_BLOCKS)
    for (int k0 = SF_LOAD(forward_starts, q); k0 < end; k0 += 8) {
      SF_READ_CHUNK(forward_panel, forward_blocks)
#  define SF_FORWARD_BLOCK(j, f, l)                                                            \
      if (k0 + j < end) {                                                                      \
        real4 yp = SF_Y4(y_quad(uint(subgroupShuffle(panel, j))));                             \
        b -= subgroupShuffle(f, l) * yp.x + subgroupShuffle(f, l + 1u) * yp.y +                \
             subgroupShuffle(f, l + 2u) * yp.z + subgroupShuffle(f, l + 3u) * yp.w;            \
      }
      SF_EACH_CHUNK_BLOCK(SF_FORWARD_BLOCK)
    }
#else
    for (int k = SF_LOAD(forward_starts, q) + int(h); k < end; k += int(H)) {
      real4 yp = SF_Y4(y_quad(uint(SF_LOAD(forward_panel, k))));
      uint at = 4u * uint(k);
      b -= SF_COLUMN(forward_blocks, at) * yp.x + SF_COLUMN(forward_blocks, at + 1u) * yp.y +
           SF_COLUMN(forward_blocks, at + 2u) * yp.z + SF_COLUMN(forward_blocks, at + 3u) * yp.w;
    }
#endif
    b = add_parts(b);
    /* T y_q = b, T's columns t0..t3 lower triangular: y_c, then b -= t_c y_c. */
    real4 t0 = SF_COLUMN(triangles, 4u * q), t1 = SF_COLUMN(triangles, 4u * q + 1u);
    real4 t2 = SF_COLUMN(triangles, 4u * q + 2u), t3 = SF_COLUMN(triangles, 4u * q + 3u);
    real4 yq;
    yq.x = b.x / t0.x;
    b -= t0 * yq.x;
    yq.y = b.y / t1.y;
    b -= t1 * yq.y;
    yq.z = b.z / t2.z;
    yq.w = (b.w - t2.w * yq.z) / t3.w;
    SF_SET_Y4(y_quad(q), yq);
  }
  /* The springs' correction, each sum in a register (no arrays of m per lane), shared by the
   * H lanes as the blocks are. */
  for (uint step = max(first, projected); step < min(last, coupled); ++step) { /* (V^T y)_4i..4i+3 */
    uint i = step - projected;
    real4 sum = real4(0);
    for (uint u = h; u < reached; u += H) sum += SF_V4(u * quads + i) * y_at(uint(SF_LOAD(spring_at, 2u + u)));
    SF_SET_Y4(y_quad(P + i), add_parts(sum));   /* padding: V's zeros */
  }
  for (uint step = max(first, coupled); step < min(last, updated); ++step) { /* (H_s V^T y)_j */
    uint j = step - coupled;
    real sum = real(0);
    for (uint k = h; k < m; k += H)
      sum += SF_LOAD(spring_coupling, (s * m + j) * m + k) * y_at(sums + k);
    set_y_at(sums + 4u * quads + j, add_parts(sum));
    if (j + 1u == m)   /* the padding after it 0, not what the work buffer held */
      for (uint c = m; c < 4u * quads; ++c) set_y_at(sums + 4u * quads + c, real(0));
  }
  for (uint step = max(first, updated); step < min(last, backward); ++step) { /* y -= V H_s V^T y */
    uint u = step - updated;
    uint at = uint(SF_LOAD(spring_at, 2u + u));
    real sum = real(0);
    for (uint i = h; i < quads; i += H) sum += dot(SF_V4(u * quads + i), SF_Y4(y_quad(P + quads + i)));
    set_y_at(at, y_at(at) - add_parts(sum));
  }
  /* r.z so far, kept in y's quad P + 2 M / 4 between dispatches (then r.z, beta). */
  uint rz_quad = P + 2u * quads;
  uint finishing = backward + P;   /* the steps of CG's d, SF_FACTOR_FINISH_QUADS of y's quads each */
  bool finishes = finish != SF_FACTOR_FINISH_NONE;
  real sum_rz = finishes && first > backward ? SF_Y4(y_quad(rz_quad)).x : real(0);
  for (uint step = max(first, backward); step < min(last, finishing); ++step) { /* L^T w = y: block column p */
    uint p = finishing - 1u - step;
    real4 a = h == 0u ? SF_Y4(y_quad(p)) : real4(0);   /* y_p once */
    int end = SF_LOAD(backward_starts, p + 1u);
#if defined(SF_SHARED_BLOCKS)
    for (int k0 = SF_LOAD(backward_starts, p); k0 < end; k0 += 8) {
      SF_READ_CHUNK(backward_panel, backward_blocks)
#  define SF_BACKWARD_BLOCK(j, f, l)                                                           \
      if (k0 + j < end) {                                                                      \
        real4 w = SF_Y4(y_quad(uint(subgroupShuffle(panel, j))));                              \
        a -= real4(dot(subgroupShuffle(f, l), w), dot(subgroupShuffle(f, l + 1u), w),          \
                   dot(subgroupShuffle(f, l + 2u), w), dot(subgroupShuffle(f, l + 3u), w));    \
      }
      SF_EACH_CHUNK_BLOCK(SF_BACKWARD_BLOCK)
    }
#else
    for (int k = SF_LOAD(backward_starts, p) + int(h); k < end; k += int(H)) {
      real4 w = SF_Y4(y_quad(uint(SF_LOAD(backward_panel, k))));
      uint at = 4u * uint(k);
      a -= real4(dot(SF_COLUMN(backward_blocks, at), w), dot(SF_COLUMN(backward_blocks, at + 1u), w),
                 dot(SF_COLUMN(backward_blocks, at + 2u), w), dot(SF_COLUMN(backward_blocks, at + 3u), w));
    }
#endif
    a = add_parts(a);
    /* T^T w_p = a, from the last: w_c = (a_c - sum_i>c T_ic w_i) / T_cc. */
    real4 t0 = SF_COLUMN(triangles, 4u * p), t1 = SF_COLUMN(triangles, 4u * p + 1u);
    real4 t2 = SF_COLUMN(triangles, 4u * p + 2u), t3 = SF_COLUMN(triangles, 4u * p + 3u);
    real4 wp;
    wp.w = a.w / t3.w;
    wp.z = (a.z - t2.w * wp.w) / t2.z;
    wp.y = (a.y - t1.z * wp.z - t1.w * wp.w) / t1.y;
    wp.x = (a.x - t0.y * wp.y - t0.z * wp.z - t0.w * wp.w) / t0.x;
    SF_SET_Y4(y_quad(p), wp);
    for (uint c = 0u; c < 4u; ++c) {
      int row = SF_LOAD(slot_rows, 4u * p + c);
      if (row < 0) continue;
      if (SF_FACTOR_STORES_Z != 0u && h == 0u && writes) z[uint(row) * S + s] = wp[c];
      if (finishes) sum_rz += SF_LOAD(r, uint(row) * S + s) * wp[c];
    }
  }
  if (!finishes) return;
  if (first < finishing && last > backward) {   /* backward steps ran here: keep r.z, or end it */
    real beta = real(0);
    if (last >= finishing) {   /* the last: r.z (lane 0 of the sigma point's H reads and writes it) */
      if (finish == SF_FACTOR_FINISH_DIRECTION && h == 0u) beta = sum_rz / rz[s];
#if defined(SF_SPLIT_BLOCK_ROWS)
      beta = subgroupShuffle(beta, s);   /* lane 0 of sigma point s's H is lane s */
#endif
      if (h == 0u && writes) rz[s] = sum_rz;
    }
    SF_SET_Y4(y_quad(rz_quad), real4(sum_rz, beta, 0, 0));
  }
  /* CG's d = z (the start) or z + beta d over y's slots, which hold z: a lane's share of a
   * step's quads (the H lanes of a sigma point hold the same y). */
  for (uint step = max(first, finishing); step < last; ++step) {
    real beta = SF_Y4(y_quad(rz_quad)).y;
    uint begin = (step - finishing) * SF_FACTOR_FINISH_QUADS;
    uint end = min(P, begin + SF_FACTOR_FINISH_QUADS);
    for (uint t = begin + h; t < end; t += H) {
      real4 w = SF_Y4(y_quad(t));
      for (uint c = 0u; c < 4u; ++c) {   /* constant bounds: unrolled */
        int row = SF_LOAD(slot_rows, 4u * t + c);
        if (row < 0 || !writes) continue;
        uint at = uint(row) * S + s;
        d[at] = finish == SF_FACTOR_FINISH_START ? w[c] : w[c] + beta * d[at];
      }
    }
  }
}
