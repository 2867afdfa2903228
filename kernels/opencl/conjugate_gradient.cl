/* conjugate_gradient: Jacobi-preconditioned CG for all sigma points at once, with per-sigma
 * scalars and a per-sigma convergence flag (host: host/reference/conjugate_gradient.h, the
 * same stopping rule |r| <= tolerance |b|).
 *
 * cg_start, then cg_iteration after every product q = A d (element_product, node_product:
 * three launches per iteration; on a CPU cg_iteration does node_product's part itself: two).
 * A sigma point that has converged (or hit the iteration cap, or broke down) is inactive and
 * left alone, so the host may enqueue several iterations between checks without changing
 * anyone's result. Two forms of these kernels:
 *  - a GPU (SF_CG_PER_GROUP = 1): a work-group owns the rows of one sigma point, or of
 *    SF_CG_SIGMA_LANES side by side (below), and reduces their dot products in the group (a
 *    fixed tree: the same bits every run); on a large mesh a work-group per partition of the
 *    rows, and three launches for what cg_iteration does in one (SF_CG_PARTITIONS, below);
 *  - a CPU (SF_CG_PER_GROUP = 0): one work-item per block of SF_CG_BLOCK sigma points goes
 *    down the rows with the block innermost, on contiguous data: vectorised, and each cache
 *    line read once (one work-item per sigma point read a line per sigma point, 16 times at
 *    S = 16). Dot products are summed in row order. The blocks are all S in one, or one per
 *    compute unit where each fills whole cache lines (OpenClEnsemble: blocks writing into
 *    one line were slower than one work-item).
 * And on a CPU with a small mesh, the whole solve in one launch (cg_solve, at the end).
 *
 * Per-sigma scalars (arrays of S): bb = b.b, rr = r.r, rz = r.z, active (1 while iterating),
 * converged (1 converged, 0 hit the cap or broke down), iterations (products done). */
#include "cg_rows.h"
#include "element_chunk.h"
#include "node_rows.h"

/* Sigma points per work-item of the blocked kernels, a divisor of S. */
#ifndef SF_CG_BLOCK
#  define SF_CG_BLOCK 1
#endif
#ifndef SF_CG_PER_GROUP
#  define SF_CG_PER_GROUP 1
#endif

/* Sigma point s's scalars after the warm start, from its sums b.b, r.r and r.z; returns
 * whether it iterates (cg_rows.h). */
static inline int sf_cg_start_scalars(uint s, real sum_bb, real sum_rr, real sum_rz,
                                      __global const real* c, __global real* bb,
                                      __global real* rr, __global real* rz, __global uint* active,
                                      __global uint* converged, __global int* iterations) {
  bool breakdown = sf_cg_start_breakdown(sum_bb, sum_rr);
  bool done = sf_cg_start_converged(breakdown, sum_bb, sum_rr, c[SF_CG_TOLERANCE2]);
  bb[s] = sum_bb;
  rr[s] = sum_rr;
  rz[s] = sum_rz;
  active[s] = done || breakdown ? 0u : 1u;
  converged[s] = done ? 1u : 0u;
  iterations[s] = 0;
  return !(done || breakdown);
}

#if SF_CG_PER_GROUP
/* Work-items per group: a power of two (the host passes the same number). */
#ifndef SF_GROUP_SIZE
#  define SF_GROUP_SIZE 64
#endif
/* Sigma lanes: a group's work-items are SF_CG_SIGMA_LANES sigma points side by side (a power
 * of two that divides SF_GROUP_SIZE), each with SF_CG_ROW_LANES row lanes: work-item i takes
 * sigma point block * SF_CG_SIGMA_LANES + i % SF_CG_SIGMA_LANES and the rows i / SF_CG_SIGMA_LANES,
 * then every SF_CG_ROW_LANES-th. The lanes of a row then read consecutive entries [row S + s]
 * (with as many lanes as S, the next row's follow), where one lane per group (a sigma point's
 * group, before) had every work-item of a warp read its own sector for one real. The host's
 * CgGroups (host/ensemble/device_limits.h) chooses the lanes; the groups are blocks of sigma
 * points: S / SF_CG_SIGMA_LANES of them, rounded up, the last one's lanes past S idle. */
#ifndef SF_CG_SIGMA_LANES
#  define SF_CG_SIGMA_LANES 1
#endif
#define SF_CG_ROW_LANES (SF_GROUP_SIZE / SF_CG_SIGMA_LANES)

/* This work-item's sigma point in block `block`, and its first row (of a group's rows). */
static inline uint sf_lane_sigma(uint block) {
  return block * SF_CG_SIGMA_LANES + get_local_id(0) % SF_CG_SIGMA_LANES;
}
static inline uint sf_row_lane(void) { return get_local_id(0) / SF_CG_SIGMA_LANES; }
/* The work-item that writes its sigma point's sums and scalars: row lane 0. */
static inline bool sf_leads(void) { return get_local_id(0) < SF_CG_SIGMA_LANES; }

/* Whether any sigma point of the block has its flag set (flags[s * stride + offset]): the same
 * answer in every work-item, so that a group with nothing to do returns at once and none
 * leaves a barrier waiting. */
static inline bool sf_block_any(__global const uint* flags, uint S, uint block, uint stride,
                                uint offset) {
  for (uint l = 0; l < SF_CG_SIGMA_LANES; ++l) {
    uint s = block * SF_CG_SIGMA_LANES + l;
    if (s < S && flags[(size_t)s * stride + offset]) return true;
  }
  return false;
}

/* Tree reduction over the row lanes of each sigma lane: every work-item gets its sigma
 * point's sum (a fixed tree: the same bits every run). */
static inline real sf_group_sum(__local real* scratch, real value) {
  uint lid = get_local_id(0);
  barrier(CLK_LOCAL_MEM_FENCE); /* the previous sum's result has been read by everyone */
  scratch[lid] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint stride = SF_GROUP_SIZE / 2; stride >= SF_CG_SIGMA_LANES; stride /= 2) {
    if (lid < stride) scratch[lid] += scratch[lid + stride];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  return scratch[lid % SF_CG_SIGMA_LANES];
}

/* Rows [begin, end) of sigma point s at the warm start, with q = A x: r = b - q,
 * z = M^-1 r, d = z; the sums b.b, r.r, r.z of the group's rows in sums[0..2]. A lane with
 * nothing to do passes begin = end. */
static inline void sf_start_rows(uint S, uint s, uint begin, uint end, __global const real* q,
                                 __global const real* b, __global const real* inverse_diagonal,
                                 __global real* r, __global real* z, __global real* d,
                                 __local real* scratch, real sums[3]) {
  real sum_bb = (real)0;
  real sum_rr = (real)0;
  real sum_rz = (real)0;
  for (uint row = begin + sf_row_lane(); row < end; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + s;
    SF_CG_START_ROW(at, q[at], b, inverse_diagonal, r, z, d, sum_bb, sum_rr, sum_rz)
  }
  sums[0] = sf_group_sum(scratch, sum_bb);
  sums[1] = sf_group_sum(scratch, sum_rr);
  sums[2] = sf_group_sum(scratch, sum_rz);
}

/* The warm start's residual and the first direction: with q = A x (x = the last step's dv,
 * from element_product and node_product), r = b - q, z = M^-1 r, d = z; bb, rr, rz; and
 * whether the warm start is already good enough. A group per block of sigma points. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_start(uint S, uint node_count, __global const real* c, __global const real* q,
              __global const real* b, __global const real* inverse_diagonal, __global real* r,
              __global real* z, __global real* d, __global real* bb, __global real* rr,
              __global real* rz, __global uint* active, __global uint* converged,
              __global int* iterations) {
  __local real scratch[SF_GROUP_SIZE];
  uint s = sf_lane_sigma(get_group_id(0));
  real sums[3];
  sf_start_rows(S, s, 0, s < S ? 3 * node_count : 0, q, b, inverse_diagonal, r, z, d, scratch, sums);
  if (sf_leads() && s < S)
    sf_cg_start_scalars(s, sums[0], sums[1], sums[2], c, bb, rr, rz, active, converged, iterations);
}

/* One CG iteration of a block of sigma points, given q = A d (node_product): alpha = rz / d.q,
 * x += alpha d, r -= alpha q, z = M^-1 r, then the convergence test (|r|^2 <= tol^2 |b|^2), the
 * cap, breakdown (a residual that is not finite: the matrix is not SPD or the input held a
 * NaN), and d = z + beta d. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_iteration(uint S, uint node_count, int max_iterations, __global const real* c,
                  __global const real* inverse_diagonal, __global real* x, __global real* r,
                  __global real* z, __global real* d, __global const real* q,
                  __global const real* bb,
                  __global real* rr, __global real* rz, __global uint* active,
                  __global uint* converged, __global int* iterations) {
  __local real scratch[SF_GROUP_SIZE];
  uint block = get_group_id(0);
  if (!sf_block_any(active, S, block, 1, 0)) return;
  uint s = sf_lane_sigma(block);
  bool live = s < S && active[s];
  uint rows = live ? 3 * node_count : 0;
  int count = live ? iterations[s] + 1 : 0;
  real rz_old = live ? rz[s] : (real)1;

  real sum_dq = (real)0;
  for (uint row = sf_row_lane(); row < rows; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + s;
    sum_dq += d[at] * q[at];
  }
  real alpha = rz_old / sf_group_sum(scratch, sum_dq);

  real sum_rr = (real)0;
  real sum_rz = (real)0;
  for (uint row = sf_row_lane(); row < rows; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + s;
    SF_CG_UPDATE_ROW(at, alpha, q[at], x, r, z, d, inverse_diagonal, sum_rr, sum_rz)
  }
  sum_rr = sf_group_sum(scratch, sum_rr);
  sum_rz = sf_group_sum(scratch, sum_rz);

  bool done = live && sf_cg_converged(sum_rr, c[SF_CG_TOLERANCE2], bb[s]);
  bool stop = !live || sf_cg_stops(done, sum_rr, count, max_iterations);
  barrier(CLK_GLOBAL_MEM_FENCE); /* everyone has read the old scalars before they change */
  if (live && sf_leads()) {
    iterations[s] = count;
    rr[s] = sum_rr;
    rz[s] = sum_rz;
    if (done) converged[s] = 1u;
    if (stop) active[s] = 0u;
  }
  /* Not a return, where only some of the group's lanes stop: with one, PoCL 3 gave the lanes
   * that went on wrong sums (unconverged sigma points in the conformance suite). */
  if (stop) rows = 0;
  real beta = sum_rz / rz_old;
  for (uint row = sf_row_lane(); row < rows; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + s;
    d[at] = z[at] + beta * d[at];
  }
}

/* Partitions: on a large mesh one group per sigma point leaves most of a GPU idle (S groups
 * of 64 work-items, each going down thousands of rows). With SF_CG_PARTITIONS = P > 1 (the
 * host's choice by the rows) the rows are cut into P contiguous partitions and every (block of
 * sigma points, partition) pair is a work-group (group g: block g / P, partition p = g % P).
 * An iteration then takes three launches after the product, each ending where a sum over all
 * rows is needed: cg_dot (d.q), cg_update (alpha; x, r, z; r.r and r.z) and cg_direction (the
 * stop test and beta; d). A group's partial sums go to `partial` [(quantity * S + s) * P + p];
 * a group that needs a sum adds the P partials itself, its row lanes each every
 * SF_CG_ROW_LANES-th and then by the tree, so every group of a sigma point gets the same bits,
 * in every run. Each group also keeps its own copy of each of its sigma points' active flag,
 * iteration count and r.z (the own_* arrays, [s * P + p]): no group reads what another group
 * of the same launch writes. Group (block, 0) writes the per-sigma scalars that the host and
 * the other kernels read. */
#ifndef SF_CG_PARTITIONS
#  define SF_CG_PARTITIONS 1
#endif
#define SF_PARTIAL_DQ 0
#define SF_PARTIAL_RR 1
#define SF_PARTIAL_RZ 2
#define SF_PARTIAL_BB 3

/* Partition p's rows: [*begin, *end). */
static inline void sf_partition_rows(uint rows, uint p, uint* begin, uint* end) {
  uint size = (rows + SF_CG_PARTITIONS - 1) / SF_CG_PARTITIONS;
  *begin = min(rows, p * size);
  *end = min(rows, *begin + size);
}

/* This group's block and partition, this work-item's sigma point, and whether it takes part:
 * s < S and, where `own_active` is given, its copy of the active flag set. */
typedef struct {
  uint block, p, s, own;
  bool live;
} sf_lane;
static inline sf_lane sf_partition_lane(uint S, __global const uint* own_active) {
  sf_lane lane;
  uint g = get_group_id(0);
  lane.block = g / SF_CG_PARTITIONS;
  lane.p = g % SF_CG_PARTITIONS;
  lane.s = sf_lane_sigma(lane.block);
  lane.own = lane.s * SF_CG_PARTITIONS + lane.p;
  lane.live = lane.s < S && (own_active == 0 || own_active[lane.own]);
  return lane;
}
/* The lane's rows of its partition, none where it does not take part. */
static inline void sf_lane_rows(sf_lane lane, uint node_count, uint* begin, uint* end) {
  sf_partition_rows(3 * node_count, lane.p, begin, end);
  if (!lane.live) *end = *begin;
}

/* Sigma point s's P partials of one quantity, summed in a fixed order (above); every
 * work-item of the group calls it. */
static inline real sf_partials_sum(__local real* scratch, __global const real* partial,
                                   uint quantity, uint S, uint s) {
  real sum = (real)0;
  if (s < S) {
    __global const real* at = partial + ((size_t)quantity * S + s) * SF_CG_PARTITIONS;
    for (uint p = sf_row_lane(); p < SF_CG_PARTITIONS; p += SF_CG_ROW_LANES) sum += at[p];
  }
  return sf_group_sum(scratch, sum);
}
/* The same in one work-item (cg_start_scalars'), in partition order. */
static inline real sf_partials_sum_serial(__global const real* partial, uint quantity, uint S, uint s) {
  __global const real* at = partial + ((size_t)quantity * S + s) * SF_CG_PARTITIONS;
  real sum = (real)0;
  for (uint p = 0; p < SF_CG_PARTITIONS; ++p) sum += at[p];
  return sum;
}

/* cg_start's first part, per partition: r = b - q, z = M^-1 r, d = z and the partial sums. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_start_partials(uint S, uint node_count, __global const real* q, __global const real* b,
                       __global const real* inverse_diagonal, __global real* r, __global real* z,
                       __global real* d, __global real* partial) {
  __local real scratch[SF_GROUP_SIZE];
  sf_lane lane = sf_partition_lane(S, 0);
  uint begin, end;
  sf_lane_rows(lane, node_count, &begin, &end);
  real sums[3];
  sf_start_rows(S, lane.s, begin, end, q, b, inverse_diagonal, r, z, d, scratch, sums);
  if (sf_leads() && lane.live) {
    partial[((size_t)SF_PARTIAL_BB * S + lane.s) * SF_CG_PARTITIONS + lane.p] = sums[0];
    partial[((size_t)SF_PARTIAL_RR * S + lane.s) * SF_CG_PARTITIONS + lane.p] = sums[1];
    partial[((size_t)SF_PARTIAL_RZ * S + lane.s) * SF_CG_PARTITIONS + lane.p] = sums[2];
  }
}

/* cg_start's second part, a work-item per sigma point: the scalars and every group's copies. */
__kernel void cg_start_scalars(uint S, __global const real* c, __global const real* partial,
                               __global real* bb, __global real* rr, __global real* rz,
                               __global uint* active, __global uint* converged,
                               __global int* iterations, __global uint* own_active,
                               __global int* own_iterations, __global real* own_rz) {
  uint s = get_global_id(0);
  if (s >= S) return;
  real sum_rz = sf_partials_sum_serial(partial, SF_PARTIAL_RZ, S, s);
  int going = sf_cg_start_scalars(s, sf_partials_sum_serial(partial, SF_PARTIAL_BB, S, s),
                                  sf_partials_sum_serial(partial, SF_PARTIAL_RR, S, s), sum_rz, c,
                                  bb, rr, rz, active, converged, iterations);
  for (uint p = 0; p < SF_CG_PARTITIONS; ++p) {
    own_active[s * SF_CG_PARTITIONS + p] = going ? 1u : 0u;
    own_iterations[s * SF_CG_PARTITIONS + p] = 0;
    own_rz[s * SF_CG_PARTITIONS + p] = sum_rz;
  }
}

/* An iteration's first part after q = A d: the partial d.q. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_dot(uint S, uint node_count, __global const real* d, __global const real* q,
            __global real* partial, __global const uint* own_active) {
  __local real scratch[SF_GROUP_SIZE];
  sf_lane lane = sf_partition_lane(S, own_active);
  if (!sf_block_any(own_active, S, lane.block, SF_CG_PARTITIONS, lane.p)) return;
  uint begin, end;
  sf_lane_rows(lane, node_count, &begin, &end);
  real sum_dq = (real)0;
  for (uint row = begin + sf_row_lane(); row < end; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + lane.s;
    sum_dq += d[at] * q[at];
  }
  sum_dq = sf_group_sum(scratch, sum_dq);
  if (sf_leads() && lane.live)
    partial[((size_t)SF_PARTIAL_DQ * S + lane.s) * SF_CG_PARTITIONS + lane.p] = sum_dq;
}

/* The second part: alpha = r.z / d.q, x += alpha d, r -= alpha q, z = M^-1 r; partial r.r, r.z. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_update(uint S, uint node_count, __global const real* inverse_diagonal, __global real* x,
               __global real* r, __global real* z, __global const real* d,
               __global const real* q, __global real* partial, __global const uint* own_active,
               __global const real* own_rz) {
  __local real scratch[SF_GROUP_SIZE];
  sf_lane lane = sf_partition_lane(S, own_active);
  if (!sf_block_any(own_active, S, lane.block, SF_CG_PARTITIONS, lane.p)) return;
  real dq = sf_partials_sum(scratch, partial, SF_PARTIAL_DQ, S, lane.s);
  real alpha = lane.live ? own_rz[lane.own] / dq : (real)0;
  uint begin, end;
  sf_lane_rows(lane, node_count, &begin, &end);
  real sum_rr = (real)0;
  real sum_rz = (real)0;
  for (uint row = begin + sf_row_lane(); row < end; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + lane.s;
    SF_CG_UPDATE_ROW(at, alpha, q[at], x, r, z, d, inverse_diagonal, sum_rr, sum_rz)
  }
  sum_rr = sf_group_sum(scratch, sum_rr);
  sum_rz = sf_group_sum(scratch, sum_rz);
  if (sf_leads() && lane.live) {
    partial[((size_t)SF_PARTIAL_RR * S + lane.s) * SF_CG_PARTITIONS + lane.p] = sum_rr;
    partial[((size_t)SF_PARTIAL_RZ * S + lane.s) * SF_CG_PARTITIONS + lane.p] = sum_rz;
  }
}

/* The third part: the stop test (as cg_iteration's), the scalars, and d = z + beta d. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_direction(uint S, uint node_count, int max_iterations, __global const real* c,
                  __global const real* z, __global real* d, __global const real* partial,
                  __global const real* bb, __global real* rr, __global real* rz,
                  __global uint* active, __global uint* converged, __global int* iterations,
                  __global uint* own_active, __global int* own_iterations,
                  __global real* own_rz) {
  __local real scratch[SF_GROUP_SIZE];
  sf_lane lane = sf_partition_lane(S, own_active);
  if (!sf_block_any(own_active, S, lane.block, SF_CG_PARTITIONS, lane.p)) return;
  int count = lane.live ? own_iterations[lane.own] + 1 : 0;
  real rz_old = lane.live ? own_rz[lane.own] : (real)1;
  real sum_rr = sf_partials_sum(scratch, partial, SF_PARTIAL_RR, S, lane.s);
  real sum_rz = sf_partials_sum(scratch, partial, SF_PARTIAL_RZ, S, lane.s);
  bool done = lane.live && sf_cg_converged(sum_rr, c[SF_CG_TOLERANCE2], bb[lane.s]);
  bool stop = !lane.live || sf_cg_stops(done, sum_rr, count, max_iterations);
  barrier(CLK_GLOBAL_MEM_FENCE); /* everyone has read the old copies before they change */
  if (sf_leads() && lane.live) {
    own_iterations[lane.own] = count;
    own_rz[lane.own] = sum_rz;
    if (stop) own_active[lane.own] = 0u;
    if (lane.p == 0) {
      iterations[lane.s] = count;
      rr[lane.s] = sum_rr;
      rz[lane.s] = sum_rz;
      if (done) converged[lane.s] = 1u;
      if (stop) active[lane.s] = 0u;
    }
  }
  real beta = sum_rz / rz_old;
  uint begin, end;
  sf_lane_rows(lane, node_count, &begin, &end);
  if (stop) end = begin;   /* not a return: as cg_iteration's */
  for (uint row = begin + sf_row_lane(); row < end; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + lane.s;
    d[at] = z[at] + beta * d[at];
  }
}
/* With the multigrid V-cycle (multigrid.cl) run after cg_start_partials or cg_update, z = M^-1 r
 * there in place of their Jacobi z: the partial r.z again, and at the start (when every group
 * runs) d = z. */
__kernel __attribute__((reqd_work_group_size(SF_GROUP_SIZE, 1, 1)))
void cg_preconditioned(uint S, uint node_count, uint start, __global const real* r,
                       __global const real* z, __global real* d, __global real* partial,
                       __global const uint* own_active) {
  __local real scratch[SF_GROUP_SIZE];
  __global const uint* flags = start ? 0 : own_active;
  sf_lane lane = sf_partition_lane(S, flags);
  if (!start && !sf_block_any(own_active, S, lane.block, SF_CG_PARTITIONS, lane.p)) return;
  uint begin, end;
  sf_lane_rows(lane, node_count, &begin, &end);
  real sum_rz = (real)0;
  for (uint row = begin + sf_row_lane(); row < end; row += SF_CG_ROW_LANES) {
    size_t at = (size_t)row * S + lane.s;
    real zi = z[at];
    sum_rz += r[at] * zi;
    if (start) d[at] = zi;
  }
  sum_rz = sf_group_sum(scratch, sum_rz);
  if (sf_leads() && lane.live)
    partial[((size_t)SF_PARTIAL_RZ * S + lane.s) * SF_CG_PARTITIONS + lane.p] = sum_rz;
}
#endif /* SF_CG_PER_GROUP */

#if !SF_CG_PER_GROUP
/* The largest block (SF_SIGMA_BLOCK = S on a CPU): the helpers' arrays; `count` is a
 * constant where they are inlined, so their loops have a fixed length. */
#define SF_BLOCK_MAX SF_SIGMA_BLOCK

/* CG's preconditioner on a CPU: Jacobi, or with SF_FACTOR = 1 sparse Cholesky factors made on
 * the host (FactorisedPreconditioner, the CPU back end's): z = P^T L^-T L^-1 P r, L by
 * columns, the diagonal first in each. One factor of the mean sigma point's system shared by
 * every sigma point, or with SF_FACTOR_PER_SIGMA = 1 each sigma point's own (the same pattern
 * and ordering; entry k of sigma point s at k S + s, or in cg_solve's blocks of their own
 * vectors block by block, below). The block's sigma points are innermost,
 * so each entry of a shared L is read once for the block; the un-permuting pass adds r.z to
 * sum_rz (one per sigma point of the block). */
#if SF_FACTOR
/* Entry k of L for the block: a value loaded once (shared), or where the block's own values
 * of it start (SF_FACTOR_PER_SIGMA); SF_L_OF(entry, b) is sigma point first + b's. */
#  if SF_FACTOR_PER_SIGMA
typedef __global const real* sf_entry;
#    define SF_L_AT(k) (factor_values + (size_t)(k) * S + first)
#    define SF_L_OF(entry, b) (entry)[b]
#  else
typedef real sf_entry;
#    define SF_L_AT(k) (factor_values[k])
#    define SF_L_OF(entry, b) (entry)
#  endif
/* The factor's buffers as the last arguments of the kernels and helpers that use them. */
#  define SF_FACTOR_ARGUMENTS                                                                \
    , __global const int *restrict factor_columns, __global const int *restrict factor_rows, \
        __global const real *restrict factor_values,                                        \
        __global const int *restrict factor_order, __global real *restrict factor_work,     \
        __global const int *restrict spring_at, __global const real *restrict spring_solves, \
        __global const real *restrict spring_coupling
#  define SF_FACTOR_PASS \
    , factor_columns, factor_rows, factor_values, factor_order, factor_work, spring_at, \
        spring_solves, spring_coupling
/* The same for block `first` of the ensemble's blocks: its own rows x count of factor_work. */
#  define SF_BLOCK_FACTOR_PASS(first, rows)                                               \
    , factor_columns, factor_rows, factor_values, factor_order,                           \
        factor_work + (size_t)(first) * (rows), spring_at, spring_solves, spring_coupling
/* SF_SPRING_ROWS = m > 0: the shared factor corrected for each sigma point's own springs at
 * m rows (host/reference/spring_correction.h) between the substitutions: spring_at[0] rows of
 * L that V = L^-1 P E reaches, at spring_at[1 ..], V there by rows ([u m + j], read once for
 * the block), and each sigma point's m x m coupling H. */
#  ifndef SF_SPRING_ROWS
#    define SF_SPRING_ROWS 0
#  endif

/* The work vector y is the block's own, [row * count + b] (factor_work, offset by the caller):
 * blocks that wrote into each other's cache lines at every entry of L would be slower than one
 * block doing all (bench/RESULTS.md, stop 46). */
static inline __attribute__((always_inline)) void sf_block_factor_solve(
    uint first, uint count, uint S, uint rows, __global const real* restrict r,
    __global real* restrict z, real* restrict sum_rz SF_FACTOR_ARGUMENTS) {
  __global real* restrict y = factor_work;
  for (uint i = 0; i < rows; ++i) {
    size_t from = (size_t)i * S + first;
    size_t to = (size_t)factor_order[i] * count;
    for (uint b = 0; b < count; ++b) y[to + b] = r[from + b];
  }
  for (uint j = 0; j < rows; ++j) { /* L y' = y: each solved entry out of the rows below */
    size_t at = (size_t)j * count;
    const sf_entry diagonal = SF_L_AT(factor_columns[j]);
    real solved[SF_BLOCK_MAX];
    for (uint b = 0; b < count; ++b) {
      solved[b] = y[at + b] / SF_L_OF(diagonal, b);
      y[at + b] = solved[b];
    }
    for (int k = factor_columns[j] + 1; k < factor_columns[j + 1]; ++k) {
      const sf_entry value = SF_L_AT(k);
      __global real* restrict below = y + (size_t)factor_rows[k] * count;
      for (uint b = 0; b < count; ++b) below[b] -= SF_L_OF(value, b) * solved[b];
    }
  }
#if SF_SPRING_ROWS
  { /* Each sigma point's own springs: y' -= V H_(first + b) V^T y' on the rows V reaches. */
    const int reached = spring_at[0];
    real projected[SF_SPRING_ROWS][SF_BLOCK_MAX];
    for (uint j = 0; j < SF_SPRING_ROWS; ++j)
      for (uint b = 0; b < count; ++b) projected[j][b] = (real)0;
    for (int u = 0; u < reached; ++u) {
      __global const real* restrict at = y + (size_t)spring_at[1 + u] * count;
      __global const real* restrict v = spring_solves + (size_t)u * SF_SPRING_ROWS;
      for (uint j = 0; j < SF_SPRING_ROWS; ++j)
        for (uint b = 0; b < count; ++b) projected[j][b] += v[j] * at[b];
    }
    real coupled[SF_SPRING_ROWS][SF_BLOCK_MAX];
    for (uint b = 0; b < count; ++b) {
      __global const real* restrict H =
          spring_coupling + (size_t)(first + b) * SF_SPRING_ROWS * SF_SPRING_ROWS;
      for (uint j = 0; j < SF_SPRING_ROWS; ++j) {
        real sum = (real)0;
        for (uint k = 0; k < SF_SPRING_ROWS; ++k) sum += H[j * SF_SPRING_ROWS + k] * projected[k][b];
        coupled[j][b] = sum;
      }
    }
    for (int u = 0; u < reached; ++u) {
      __global real* restrict at = y + (size_t)spring_at[1 + u] * count;
      __global const real* restrict v = spring_solves + (size_t)u * SF_SPRING_ROWS;
      for (uint j = 0; j < SF_SPRING_ROWS; ++j)
        for (uint b = 0; b < count; ++b) at[b] -= v[j] * coupled[j][b];
    }
  }
#endif
  for (uint j = rows; j-- > 0;) { /* L^T x = y', from the last row up */
    size_t at = (size_t)j * count;
    /* Two partial sums, the entries taken in pairs: one sum's chain of dependent additions
     * was this loop's time on a small factor (the liver's, in cache). */
    real sum[SF_BLOCK_MAX];
    real other_sum[SF_BLOCK_MAX];
    for (uint b = 0; b < count; ++b) sum[b] = other_sum[b] = (real)0;
    int k = factor_columns[j] + 1;
    const int end = factor_columns[j + 1];
    for (; k + 1 < end; k += 2) {
      const sf_entry value = SF_L_AT(k);
      const sf_entry other_value = SF_L_AT(k + 1);
      __global const real* restrict below = y + (size_t)factor_rows[k] * count;
      __global const real* restrict other_below = y + (size_t)factor_rows[k + 1] * count;
      for (uint b = 0; b < count; ++b) {
        sum[b] += SF_L_OF(value, b) * below[b];
        other_sum[b] += SF_L_OF(other_value, b) * other_below[b];
      }
    }
    if (k < end) {
      const sf_entry value = SF_L_AT(k);
      __global const real* restrict below = y + (size_t)factor_rows[k] * count;
      for (uint b = 0; b < count; ++b) sum[b] += SF_L_OF(value, b) * below[b];
    }
    const sf_entry diagonal = SF_L_AT(factor_columns[j]);
    for (uint b = 0; b < count; ++b) y[at + b] = (y[at + b] - (sum[b] + other_sum[b])) / SF_L_OF(diagonal, b);
  }
  for (uint i = 0; i < rows; ++i) { /* z, un-permuted, and r.z in row order */
    size_t to = (size_t)i * S + first;
    size_t from = (size_t)factor_order[i] * count;
    for (uint b = 0; b < count; ++b) {
      real zi = y[from + b];
      z[to + b] = zi;
      sum_rz[b] += r[to + b] * zi;
    }
  }
}
#else
#  define SF_FACTOR_ARGUMENTS
#  define SF_FACTOR_PASS
#  define SF_BLOCK_FACTOR_PASS(first, rows)
#endif

/* The warm start of the block first .. first + count - 1, given q = A x: r = b - q,
 * z = M^-1 r, d = z, the scalars and the flags. Returns whether any of them goes on. */
static inline __attribute__((always_inline)) int sf_block_cg_start(
    uint first, uint count, uint S, uint rows, __global const real* restrict c,
    __global const real* restrict q, __global const real* restrict b,
    __global const real* restrict inverse_diagonal, __global real* restrict r,
    __global real* restrict z, __global real* restrict d, __global real* restrict bb,
    __global real* restrict rr, __global real* restrict rz, __global uint* restrict active,
    __global uint* restrict converged, __global int* restrict iterations SF_FACTOR_ARGUMENTS) {
  real sum_bb[SF_BLOCK_MAX];
  real sum_rr[SF_BLOCK_MAX];
  real sum_rz[SF_BLOCK_MAX];
  for (uint i = 0; i < count; ++i) sum_bb[i] = sum_rr[i] = sum_rz[i] = (real)0;
#if SF_FACTOR
  /* r = b - q and the sums b.b, r.r; z from the factor, with r.z; d = z. */
  for (uint row = 0; row < rows; ++row) {
    for (uint i = 0; i < count; ++i) {
      size_t at = (size_t)row * S + first + i;
      SF_CG_START_R_ROW(at, q[at], b, r, sum_bb[i], sum_rr[i])
    }
  }
  sf_block_factor_solve(first, count, S, rows, r, z, sum_rz SF_FACTOR_PASS);
  for (uint row = 0; row < rows; ++row)
    for (uint i = 0; i < count; ++i) {
      size_t at = (size_t)row * S + first + i;
      d[at] = z[at];
    }
#else
  for (uint row = 0; row < rows; ++row) {
    for (uint i = 0; i < count; ++i) {
      size_t at = (size_t)row * S + first + i;
      SF_CG_START_ROW(at, q[at], b, inverse_diagonal, r, z, d, sum_bb[i], sum_rr[i], sum_rz[i])
    }
  }
#endif
  int any = 0;
  for (uint i = 0; i < count; ++i)
    any |= sf_cg_start_scalars(first + i, sum_bb[i], sum_rr[i], sum_rz[i], c, bb, rr, rz, active,
                               converged, iterations);
  return any;
}

/* One iteration of the block, given q = A d: d.q, alpha (0 for a sigma point that is done),
 * x += alpha d, r -= alpha q, z = M^-1 r, the convergence test, the cap and breakdown (a
 * residual that is not finite), and d = z + beta d for those that go on. Returns whether any
 * of them goes on. */
static inline __attribute__((always_inline)) int sf_block_cg_iteration(
    uint first, uint count, uint S, uint rows, int max_iterations, __global const real* restrict c,
    __global const real* restrict inverse_diagonal, __global real* restrict x,
    __global real* restrict r, __global real* restrict z, __global real* restrict d,
    __global const real* restrict q, __global const real* restrict bb,
    __global real* restrict rr, __global real* restrict rz, __global uint* restrict active,
    __global uint* restrict converged, __global int* restrict iterations SF_FACTOR_ARGUMENTS) {
  int going[SF_BLOCK_MAX];
  int any = 0;
  for (uint i = 0; i < count; ++i) {
    going[i] = active[first + i] != 0u;
    any |= going[i];
  }
  if (!any) return 0;
  real sum_dq[SF_BLOCK_MAX];
  for (uint i = 0; i < count; ++i) sum_dq[i] = (real)0;
  for (uint row = 0; row < rows; ++row)
    for (uint i = 0; i < count; ++i) {
      size_t at = (size_t)row * S + first + i;
      sum_dq[i] += d[at] * q[at];
    }
  real alpha[SF_BLOCK_MAX];
  real rr_new[SF_BLOCK_MAX];
  real rz_new[SF_BLOCK_MAX];
  for (uint i = 0; i < count; ++i) {
    alpha[i] = going[i] ? rz[first + i] / sum_dq[i] : (real)0;
    rr_new[i] = rz_new[i] = (real)0;
  }
#if SF_FACTOR
  /* x += alpha d, r -= alpha q and r.r; z from the factor, with r.z. */
  for (uint row = 0; row < rows; ++row) {
    for (uint i = 0; i < count; ++i) {
      size_t at = (size_t)row * S + first + i;
      SF_CG_UPDATE_XR_ROW(at, alpha[i], q[at], x, r, d, rr_new[i])
    }
  }
  sf_block_factor_solve(first, count, S, rows, r, z, rz_new SF_FACTOR_PASS);
#else
  for (uint row = 0; row < rows; ++row) {
    for (uint i = 0; i < count; ++i) {
      size_t at = (size_t)row * S + first + i;
      SF_CG_UPDATE_ROW(at, alpha[i], q[at], x, r, z, d, inverse_diagonal, rr_new[i], rz_new[i])
    }
  }
#endif
  real beta[SF_BLOCK_MAX];
  any = 0;
  for (uint i = 0; i < count; ++i) {
    uint s = first + i;
    beta[i] = (real)1;
    if (!going[i]) continue;
    int products = iterations[s] + 1;
    bool done = sf_cg_converged(rr_new[i], c[SF_CG_TOLERANCE2], bb[s]);
    going[i] = !sf_cg_stops(done, rr_new[i], products, max_iterations);
    beta[i] = rz_new[i] / rz[s];
    iterations[s] = products;
    rr[s] = rr_new[i];
    rz[s] = rz_new[i];
    if (done) converged[s] = 1u;
    if (!going[i]) active[s] = 0u;
    any |= going[i];
  }
  if (!any) return 0;
  for (uint row = 0; row < rows; ++row) {
    for (uint i = 0; i < count; ++i) {
      size_t at = (size_t)row * S + first + i;
      d[at] = going[i] ? z[at] + beta[i] * d[at] : d[at];
    }
  }
  return 1;
}

/* q = A d for the block, from the element chunks' copies of K d (element_product.cl, summed
 * in chunk order) and the nodal terms (node_rows.h's row, as node_product's): done here so
 * that the iteration needs no launch of its own for it and finds q in cache. A node's springs
 * and mass are found once for its three rows. The step constants and springs are sigma point
 * first + i's; d, q and the copies are [row * stride + offset + i] (the ensemble's layout:
 * stride S, offset first; a block's own vectors in cg_solve: stride count, offset 0). */
static inline __attribute__((always_inline)) void sf_block_node_product(
    uint first, uint count, uint chunks, uint S, uint stride, uint offset, uint node_count,
    __global const real* restrict c,
    __global const int* restrict ligament_offsets, __global const int* restrict ligament_of_node,
    __global const real* restrict ligament_k, __global const real* restrict control_k,
    __global const real* restrict mass, __global const real* restrict d,
    __global const real* restrict element_out, __global real* restrict q) {
  const size_t copy_size = (size_t)3 * node_count * stride;
  /* The block's factors of A (step_constants.h), read once: the same at every node. */
  real stiffness_factor[SF_BLOCK_MAX];
  real young_scale[SF_BLOCK_MAX];
  real mass_factor[SF_BLOCK_MAX];
  for (uint i = 0; i < count; ++i) {
    stiffness_factor[i] = SF_SIGMA_CONSTANT(c, SF_STIFFNESS_FACTOR, first + i, S);
    young_scale[i] = SF_SIGMA_CONSTANT(c, SF_YOUNG_SCALE, first + i, S);
    mass_factor[i] = SF_SIGMA_CONSTANT(c, SF_MASS_FACTOR, first + i, S);
  }
  for (uint n = 0; n < node_count; ++n) {
    real spring[SF_BLOCK_MAX];
    real m[SF_BLOCK_MAX];
    for (uint i = 0; i < count; ++i) {
      SF_NODE_SPRING(ligament_offsets, ligament_of_node, ligament_k, control_k, n, first + i, S,
                     spring[i])
      m[i] = sf_solver_mass(mass[n], spring[i]);
    }
    SF_UNROLL
    for (int k = 0; k < 3; ++k) {
      size_t row = ((size_t)3 * n + k) * stride + offset;
      real sum[SF_BLOCK_MAX];
      for (uint i = 0; i < count; ++i) sum[i] = (real)0;
      for (uint chunk = 0; chunk < chunks; ++chunk)
        for (uint i = 0; i < count; ++i) sum[i] += element_out[chunk * copy_size + row + i];
      for (uint i = 0; i < count; ++i)
        q[row + i] = sf_system_row(stiffness_factor[i], young_scale[i], mass_factor[i], sum[i],
                                   spring[i], m[i], d[row + i]);
    }
  }
}

__kernel void cg_start(uint S, uint node_count, __global const real* restrict c,
                       __global const real* restrict q, __global const real* restrict b,
                       __global const real* restrict inverse_diagonal, __global real* restrict r,
                       __global real* restrict z, __global real* restrict d,
                       __global real* restrict bb, __global real* restrict rr,
                       __global real* restrict rz, __global uint* restrict active,
                       __global uint* restrict converged, __global int* restrict iterations
                       SF_FACTOR_ARGUMENTS) {
  uint first = (uint)get_global_id(0) * SF_CG_BLOCK;
  if (first >= S) return;
  /* The vectors' stride S as the constant SF_SIGMA_BLOCK (equal on a CPU): so the compiler
   * vectorises the rows' loops over the block (stop 46: cg_solve 670-720 -> 600 us a launch
   * on the liver filter step). */
  sf_block_cg_start(first, SF_CG_BLOCK, SF_SIGMA_BLOCK, 3 * node_count, c, q, b, inverse_diagonal,
                    r, z, d, bb, rr, rz, active, converged, iterations
                    SF_BLOCK_FACTOR_PASS(first, 3 * node_count));
}

/* One iteration after element_product: q = A d (sf_block_node_product), then the update. */
__kernel void cg_iteration(uint S, uint node_count, int max_iterations,
                           __global const real* restrict c,
                           __global const real* restrict inverse_diagonal,
                           __global real* restrict x, __global real* restrict r,
                           __global real* restrict z, __global real* restrict d,
                           __global real* restrict q, __global const real* restrict bb,
                           __global real* restrict rr, __global real* restrict rz,
                           __global uint* restrict active, __global uint* restrict converged,
                           __global int* restrict iterations,
                           __global const int* restrict ligament_offsets,
                           __global const int* restrict ligament_of_node,
                           __global const real* restrict ligament_k,
                           __global const real* restrict control_k,
                           __global const real* restrict mass,
                           __global const real* restrict element_out SF_FACTOR_ARGUMENTS) {
  uint first = (uint)get_global_id(0) * SF_CG_BLOCK;
  if (first >= S) return;
  int any = 0;
  for (uint i = 0; i < SF_CG_BLOCK; ++i) any |= active[first + i] != 0u;
  if (!any) return;
  sf_block_node_product(first, SF_CG_BLOCK, SF_ELEMENT_CHUNKS, S, SF_SIGMA_BLOCK, first,
                        node_count, c, ligament_offsets, ligament_of_node, ligament_k, control_k,
                        mass, d, element_out, q);
  sf_block_cg_iteration(first, SF_CG_BLOCK, SF_SIGMA_BLOCK, 3 * node_count, max_iterations, c,
                        inverse_diagonal, x, r, z, d, q, bb, rr, rz, active, converged, iterations
                        SF_BLOCK_FACTOR_PASS(first, 3 * node_count));
}

/* cg_solve's work for one block (the sigma points first .. first + count - 1): the vectors
 * b .. copy are [row * count + i] (a block's own, or the ensemble's when the block is all S),
 * the per-sigma scalars and flags are given from the block's first (bb[i] is sigma point
 * first + i's); the step constants, frames and springs are the ensemble's (of S). */
static inline __attribute__((always_inline)) void sf_cg_solve_block(
    uint first, uint count, uint S, uint rows, uint element_count,
    uint node_count, int max_iterations, __global const real* restrict c,
    __global const int* restrict nodes, __global const real* restrict rest,
    __global const real* restrict frames, __global const int* restrict ligament_offsets,
    __global const int* restrict ligament_of_node, __global const real* restrict ligament_k,
    __global const real* restrict control_k, __global const real* restrict mass,
    __global const real* restrict b, __global const real* restrict inverse_diagonal,
    __global real* restrict x, __global real* restrict r, __global real* restrict z,
    __global real* restrict d, __global real* restrict q, __global real* restrict copy,
    __global real* restrict bb, __global real* restrict rr, __global real* restrict rz,
    __global uint* restrict active, __global uint* restrict converged,
    __global int* restrict iterations SF_FACTOR_ARGUMENTS) {
  sf_element_chunk_products(0, element_count, first, count, S, count, node_count, nodes, rest,
                            frames, c, x, copy);
  sf_block_node_product(first, count, 1, S, count, 0, node_count, c, ligament_offsets,
                        ligament_of_node, ligament_k, control_k, mass, x, copy, q);
  int any = sf_block_cg_start(0, count, count, rows, c, q, b, inverse_diagonal, r, z, d,
                              bb, rr, rz, active, converged, iterations SF_FACTOR_PASS);
  while (any) {
    sf_element_chunk_products(0, element_count, first, count, S, count, node_count, nodes, rest,
                              frames, c, d, copy);
    sf_block_node_product(first, count, 1, S, count, 0, node_count, c, ligament_offsets,
                          ligament_of_node, ligament_k, control_k, mass, d, copy, q);
    any = sf_block_cg_iteration(0, count, count, rows, max_iterations, c, inverse_diagonal,
                                x, r, z, d, q, bb, rr, rz, active, converged, iterations
                                SF_FACTOR_PASS);
  }
}

/* The whole solve in one launch, for small meshes: one work-item per block of
 * SF_CG_SOLVE_BLOCK sigma points (all S, or one block per compute unit) does the products
 * itself (one chunk of all the elements into its copy of K d, then q), so a step costs one
 * launch instead of two per iteration. Where a launch costs several microseconds (PoCL) and
 * an iteration's work is tens of them, that is most of the time (the liver filter step).
 * With more than one block, each works on its own vectors ([row * SF_CG_SOLVE_BLOCK + i], in
 * element_out, which the element outputs leave free once node_rhs has read them; its factor
 * work in factor_work): blocks in the ensemble's layout would write into each other's cache
 * lines at every row. The host sizes element_out for that (SF_CG_SOLVE_VECTORS), picks the
 * blocks and uses this kernel on meshes small enough for it to pay (OpenClEnsemble). */
#ifndef SF_CG_SOLVE_BLOCK
#  define SF_CG_SOLVE_BLOCK SF_SIGMA_BLOCK
#endif
#define SF_CG_SOLVE_BLOCKS (SF_SIGMA_BLOCK / SF_CG_SOLVE_BLOCK)
__kernel void cg_solve(uint S, uint element_count, uint node_count, int max_iterations,
                       __global const real* restrict c, __global const int* restrict nodes,
                       __global const real* restrict rest, __global const real* restrict frames,
                       __global const int* restrict ligament_offsets,
                       __global const int* restrict ligament_of_node,
                       __global const real* restrict ligament_k,
                       __global const real* restrict control_k, __global const real* restrict mass,
                       __global const real* restrict b, __global const real* restrict inverse_diagonal,
                       __global real* restrict x, __global real* restrict r,
                       __global real* restrict z, __global real* restrict d,
                       __global real* restrict q, __global real* restrict element_out,
                       __global real* restrict bb, __global real* restrict rr,
                       __global real* restrict rz, __global uint* restrict active,
                       __global uint* restrict converged, __global int* restrict iterations
                       SF_FACTOR_ARGUMENTS) {
  const uint block = (uint)get_global_id(0);
  if (block >= SF_CG_SOLVE_BLOCKS) return;
  const uint first = block * SF_CG_SOLVE_BLOCK;
  const uint rows = 3 * node_count;
#if SF_CG_SOLVE_BLOCKS > 1
  /* The block's own vectors: x, b, the inverse diagonal, r, z, d, q and its copy of K d. */
  const size_t size = (size_t)rows * SF_CG_SOLVE_BLOCK;
  __global real* restrict own = element_out + (size_t)block * SF_CG_SOLVE_VECTORS * size;
  __global real* restrict own_x = own;
  __global real* restrict own_b = own + size;
  __global real* restrict own_inverse_diagonal = own + 2 * size;
  for (uint row = 0; row < rows; ++row)
    for (uint i = 0; i < SF_CG_SOLVE_BLOCK; ++i) {
      const size_t at = (size_t)row * S + first + i;
      const size_t own_at = (size_t)row * SF_CG_SOLVE_BLOCK + i;
      own_x[own_at] = x[at];
      own_b[own_at] = b[at];
#  if !SF_FACTOR
      own_inverse_diagonal[own_at] = inverse_diagonal[at];
#  endif
    }
#  if SF_FACTOR_PER_SIGMA
  /* Each block's own factors follow each other: the block's entry k of its sigma point i at
   * k SF_CG_SOLVE_BLOCK + i (factor_columns[rows] is L's entry count). */
#    define SF_OWN_FACTOR_PASS , factor_columns, factor_rows,                                  \
        factor_values + (size_t)block * (size_t)factor_columns[rows] * SF_CG_SOLVE_BLOCK,     \
        factor_order, factor_work + (size_t)block * size, spring_at, spring_solves, spring_coupling
#  elif SF_FACTOR
  /* The block's sigma points are 0 .. count - 1 in the helpers: their couplings from first's. */
#    define SF_OWN_FACTOR_PASS , factor_columns, factor_rows, factor_values, factor_order, \
        factor_work + (size_t)block * size, spring_at, spring_solves,                      \
        spring_coupling + (size_t)first * SF_SPRING_ROWS * SF_SPRING_ROWS
#  else
#    define SF_OWN_FACTOR_PASS
#  endif
  sf_cg_solve_block(first, SF_CG_SOLVE_BLOCK, S, rows, element_count, node_count, max_iterations,
                    c, nodes, rest, frames, ligament_offsets, ligament_of_node,
                    ligament_k, control_k, mass, own_b, own_inverse_diagonal, own_x,
                    own + 3 * size, own + 4 * size, own + 5 * size, own + 6 * size,
                    own + 7 * size, bb + first, rr + first, rz + first, active + first,
                    converged + first, iterations + first SF_OWN_FACTOR_PASS);
#  undef SF_OWN_FACTOR_PASS
  for (uint row = 0; row < rows; ++row)
    for (uint i = 0; i < SF_CG_SOLVE_BLOCK; ++i)
      x[(size_t)row * S + first + i] = own_x[(size_t)row * SF_CG_SOLVE_BLOCK + i];
#else
  /* One block: the ensemble's vectors (SF_SIGMA_BLOCK = S on a CPU, a constant here). */
  sf_cg_solve_block(0, SF_SIGMA_BLOCK, S, rows, element_count, node_count,
                    max_iterations, c, nodes, rest, frames, ligament_offsets, ligament_of_node,
                    ligament_k, control_k, mass, b, inverse_diagonal, x, r, z, d, q, element_out,
                    bb, rr, rz, active, converged, iterations SF_FACTOR_PASS);
#endif
}
#endif
