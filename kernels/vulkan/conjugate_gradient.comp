/* conjugate_gradient: Jacobi-preconditioned CG for all sigma points at once, with per-sigma
 * scalars and a per-sigma convergence flag (as kernels/opencl/conjugate_gradient.cl; host:
 * host/reference/conjugate_gradient.h, the same stopping rule |r| <= tolerance |b|).
 * Compiled once per entry point (cmake/compile_glsl.cmake):
 *   -DSF_ENTRY_CG_START      cg_start:     the warm start's residual and first direction
 *   -DSF_ENTRY_CG_ITERATION  cg_iteration: one iteration after the product q = A d
 *   -DSF_ENTRY_CG_NODE_ITERATION  cg_node_iteration: the same after element_product alone,
 *                            forming q = A d itself from the element outputs (node_product's
 *                            rows): two dispatches an iteration instead of three, with one
 *                            partition, where lavapipe's cost per dispatch outweighs the
 *                            work (VulkanEnsemble)
 * and, for partitions (below), cg_start_partials and cg_start_scalars for cg_start, and
 * cg_dot, cg_update and cg_direction for cg_iteration.
 *
 * With a factor as the preconditioner (one partition; host/vulkan/vulkan_factor_solve.h),
 * factor_solve.comp forms z = M^-1 r after the start and after each iteration's update, and
 * r.z and the direction after it (its SF_FACTOR_FINISH_*), where Jacobi's z lets the shaders
 * above do them at once; these stop before:
 *   -DSF_ENTRY_CG_ITERATION_FACTOR, -DSF_ENTRY_CG_NODE_ITERATION_FACTOR  cg_iteration and
 *                            cg_node_iteration up to the stop test: no r.z, no new direction
 *   -DSF_ENTRY_CG_START_FACTOR      cg_start_factor: cg_start's r = b - A x and sums, no z or d
 *
 * With the multigrid V-cycle as the preconditioner (multigrid.comp; host/vulkan/vulkan_multigrid.h),
 * CG runs in the partitions' shaders (with P = 1 on a small mesh) and the V-cycle writes z over
 * Jacobi's after cg_start_partials and cg_update; then
 *   -DSF_ENTRY_CG_PRECONDITIONED    cg_preconditioned: the partition's r.z again, and at the
 *                            start (push constant p = 1, every group) d = z
 *
 * One work-group per sigma point owns every row of that sigma point, so the dot products are
 * reduced inside the group by a fixed tree (the same bits every run) and the rest of a CG
 * iteration after the product is one dispatch. The group size is specialization constant 0
 * (a power of two, set by the host). A sigma point that is inactive (converged, hit the cap
 * or broke down) returns at once, so the host records many iterations in one command buffer
 * without changing anyone's result.
 *
 * Partitions: on a large mesh a group per sigma point leaves most of a GPU idle. With
 * specialization constant 1, P > 1, each sigma point's nodes are cut into P contiguous
 * partitions and every (sigma point, partition) pair is a work-group (group g: s = g / P,
 * p = g % P), as the OpenCL kernels' SF_CG_PARTITIONS (whose comment says how the partial
 * sums, summed in partition order, and each group's own copies of its scalars keep every
 * group's bits the same and no group reading what another writes).
 *
 * Lanes over sigma points (specialization constant 2, SF_LANE_ROWS = J > 0): a group's G lanes
 * are G / J sigma points, J lanes each, lane (j, s) walking every J-th node of its sigma point
 * (of its partition) from the j-th and summing its dot products itself, in node order; the J
 * parts are then added in lane order by subgroup shuffles (J > 1 in one partition on a CPU
 * device: the entries compiled with SF_LANE_SHUFFLES, SPIR-V 1.3; no tree, no barriers) or by
 * the group's tree stopped at the G / J sigma points (the partitions' shaders). The host
 * dispatches ceil(J S / G) groups a partition. On a CPU device (one partition) the lanes of a
 * vector then take one node (J = 1) or J at once, so that its loops over element corners and
 * ligaments turn alike in its lanes, and read the node's data at one address, where a group
 * over a sigma point's nodes turns each loop as often as the busiest of 8 nodes needs
 * (bench/RESULTS.md, stop 57). On a GPU (partitions, since stop 63, as OpenCL's
 * SF_CG_SIGMA_LANES) a warp's lanes read runs of G / J consecutive entries [row S + s] instead
 * of each its own 32-byte sector for 4 bytes; a lane whose sigma point is past S or done skips
 * its rows but keeps to the group's barriers.
 *
 * Per-sigma scalars (arrays of S): bb = b.b, rr = r.r, rz = r.z, active (1 while iterating),
 * converged (1 converged, 0 hit the cap or broke down), iterations (products done). */
#version 450
#extension GL_GOOGLE_include_directive : require
#if defined(SF_LANE_SHUFFLES)
#  extension GL_KHR_shader_subgroup_shuffle : require
#endif

#if defined(SF_ENTRY_CG_START_FACTOR)
#  define SF_ENTRY_CG_START
#  define SF_FACTOR
#elif defined(SF_ENTRY_CG_ITERATION_FACTOR)
#  define SF_ENTRY_CG_ITERATION
#  define SF_FACTOR
#elif defined(SF_ENTRY_CG_NODE_ITERATION_FACTOR)
#  define SF_ENTRY_CG_NODE_ITERATION
#  define SF_FACTOR
#endif

#if defined(SF_ENTRY_CG_START) || defined(SF_ENTRY_CG_START_PARTIALS) || \
    defined(SF_ENTRY_CG_START_SCALARS)
#  define SF_START_FAMILY
#  include "node_assembly.h"
#else
#  include "ensemble_layout.h"
#endif
#include "cg_rows.h"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint SF_PARTITIONS = 1u;
layout(constant_id = 2) const uint SF_LANE_ROWS = 0u;
const bool SF_SIGMA_LANES = SF_LANE_ROWS > 0u;
/* With lanes over sigma points: the group's sigma points, this lane's among them and its part. */
const uint SF_LANE_SIGMAS = SF_SIGMA_LANES ? gl_WorkGroupSize.x / SF_LANE_ROWS : 1u;
uint sf_lane_sigma() { return gl_LocalInvocationID.x % SF_LANE_SIGMAS; }
uint sf_lane_part() { return gl_LocalInvocationID.x / SF_LANE_SIGMAS; }

/* This invocation's partition and sigma point (group g: sigma block g / P, partition g % P),
 * its first row (node) and the step to its next, and whether it stores the sigma point's
 * scalars: by lanes over sigma points or a group a sigma point. */
uint sf_partition() { return gl_WorkGroupID.x % SF_PARTITIONS; }
uint sf_sigma_point() {
  uint block = gl_WorkGroupID.x / SF_PARTITIONS;
  return SF_SIGMA_LANES ? block * SF_LANE_SIGMAS + sf_lane_sigma() : block;
}
uint sf_first_row() { return SF_SIGMA_LANES ? sf_lane_part() : gl_LocalInvocationID.x; }
uint sf_row_step() { return SF_SIGMA_LANES ? SF_LANE_ROWS : gl_WorkGroupSize.x; }
bool sf_leads() { return SF_SIGMA_LANES ? sf_lane_part() == 0u : gl_LocalInvocationID.x == 0u; }
/* Everyone in a group over a sigma point has read its old scalars before they change. */
void sf_scalars_read() {
  if (!SF_SIGMA_LANES) {
    memoryBarrierBuffer();
    barrier();
  }
}

shared real scratch[gl_WorkGroupSize.x];

/* Tree reduction of one value per invocation of the group, returned to every invocation; with
 * lanes over sigma points the J parts of the lane's sigma point: by shuffles, in lane order, or
 * by the tree stopped at G / J (lane j s's partners are j' s: the same sigma point). */
real sf_group_sum(real value) {
  if (SF_SIGMA_LANES) {
    if (SF_LANE_ROWS == 1u) return value;
#if defined(SF_LANE_SHUFFLES)
    real total = real(0);
    for (uint j = 0u; j < 8u; ++j)   /* constant bounds: unrolled */
      if (j < SF_LANE_ROWS) total += subgroupShuffle(value, j * SF_LANE_SIGMAS + sf_lane_sigma());
    return total;
#endif
  }
  uint lid = gl_LocalInvocationID.x;
  barrier(); /* the previous sum's result has been read by everyone */
  scratch[lid] = value;
  memoryBarrierShared();
  barrier();
  for (uint stride = gl_WorkGroupSize.x / 2u; stride >= SF_LANE_SIGMAS; stride /= 2u) {
    if (lid < stride) scratch[lid] += scratch[lid + stride];
    memoryBarrierShared();
    barrier();
  }
  return scratch[sf_lane_sigma()];
}

/* Partition p's nodes: [begin, end) of the push constant's node count. */
void sf_partition_nodes(uint p, out uint begin, out uint end) {
  uint size = (sf_push.count + SF_PARTITIONS - 1u) / SF_PARTITIONS;
  begin = min(sf_push.count, p * size);
  end = min(sf_push.count, begin + size);
}

/* The partial sums' quantities: partial[(quantity * S + s) * P + p]. */
#define SF_PARTIAL_DQ 0u
#define SF_PARTIAL_RR 1u
#define SF_PARTIAL_RZ 2u
#define SF_PARTIAL_BB 3u

/* Sigma point s's P partials of one quantity, summed in partition order (needs `partial`). */
#define SF_PARTIALS_SUM(quantity, S, s, sum_)                                    \
  sum_ = real(0);                                                                \
  for (uint p_ = 0u; p_ < SF_PARTITIONS; ++p_)                                   \
    sum_ += partial[((quantity) * (S) + (s)) * SF_PARTITIONS + p_];

#if defined(SF_START_FAMILY)
/* One descriptor set for the three start shaders: the node rows' buffers (node_assembly.h), then these. */
SF_READ_REALS(SF_CG_START_ELEMENT_OUT, element_out)
SF_READ_REALS(SF_CG_START_RHS, b)
SF_READ_REALS(SF_CG_START_INVERSE_DIAGONAL, inverse_diagonal)
SF_READ_REALS(SF_CG_START_DV, x)
layout(std430, binding = SF_CG_START_R) restrict writeonly buffer R { real r[]; };
layout(std430, binding = SF_CG_START_Z) restrict writeonly buffer Z { real z[]; };
layout(std430, binding = SF_CG_START_D) restrict writeonly buffer D { real d[]; };
layout(std430, binding = SF_CG_START_BB) restrict writeonly buffer BB { real bb[]; };
layout(std430, binding = SF_CG_START_RR) restrict writeonly buffer RR { real rr[]; };
layout(std430, binding = SF_CG_START_RZ) restrict writeonly buffer RZ { real rz[]; };
layout(std430, binding = SF_CG_START_ACTIVE) restrict writeonly buffer Active { uint active_flags[]; };
layout(std430, binding = SF_CG_START_CONVERGED) restrict writeonly buffer Converged { uint converged[]; };
layout(std430, binding = SF_CG_START_ITERATIONS) restrict writeonly buffer Iterations { int iterations[]; };
layout(std430, binding = SF_CG_START_PARTIAL) restrict buffer Partial { real partial[]; };
layout(std430, binding = SF_CG_START_OWN_ACTIVE) restrict writeonly buffer OwnActive { uint own_active[]; };
layout(std430, binding = SF_CG_START_OWN_ITERATIONS) restrict writeonly buffer OwnIterations { int own_iterations[]; };
layout(std430, binding = SF_CG_START_OWN_RZ) restrict writeonly buffer OwnRz { real own_rz[]; };

/* Over nodes [begin, end) of sigma point s, with q = A x (x = the last step's dv, products
 * in element_out): r = b - q, z = M^-1 r, d = z; and the group's sums b.b, r.r, r.z. */
void sf_start_rows(uint s, uint S, uint begin, uint end, out real sum_bb, out real sum_rr,
                   out real sum_rz) {
  sum_bb = real(0);
  sum_rr = real(0);
  sum_rz = real(0);
  for (uint n = begin + sf_first_row(); n < end; n += sf_row_step()) {
    real spring;
    SF_SPRING_OF(n, s, S, spring)
    real m = sf_solver_mass(SF_LOAD(mass, n), spring);
    real Kd[3];
    SF_CORNER_SUMS(element_out, incidence_offsets, incidence, n, s, S, Kd)
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
      real q = SF_SYSTEM_ROW(c, s, S, Kd[k], spring, m, SF_LOAD(x, row));
#  if defined(SF_FACTOR) /* z, d and r.z are factor_solve's */
      SF_CG_START_R_ROW(row, q, b, r, sum_bb, sum_rr)
#  else
      SF_CG_START_ROW(row, q, b, inverse_diagonal, r, z, d, sum_bb, sum_rr, sum_rz)
#  endif
    }
  }
  sum_bb = sf_group_sum(sum_bb);
  sum_rr = sf_group_sum(sum_rr);
  sum_rz = sf_group_sum(sum_rz);
}

/* Sigma point s's scalars after the warm start; whether it iterates (cg_rows.h). */
bool sf_start_scalars(uint s, real sum_bb, real sum_rr, real sum_rz) {
  bool breakdown = sf_cg_start_breakdown(sum_bb, sum_rr);
  bool done = sf_cg_start_converged(breakdown, sum_bb, sum_rr, SF_LOAD(c, SF_CG_TOLERANCE2));
  bb[s] = sum_bb;
  rr[s] = sum_rr;
  rz[s] = sum_rz;
  active_flags[s] = done || breakdown ? 0u : 1u;
  converged[s] = done ? 1u : 0u;
  iterations[s] = 0;
  return !(done || breakdown);
}

#  if defined(SF_ENTRY_CG_START)
void main() {
  uint s = sf_sigma_point();
  if (s >= sf_push.S) return;   /* lanes over sigma points: past the last */
  real sum_bb, sum_rr, sum_rz;
  sf_start_rows(s, sf_push.S, 0u, sf_push.count, sum_bb, sum_rr, sum_rz);
  if (sf_leads()) sf_start_scalars(s, sum_bb, sum_rr, sum_rz);
}

#  elif defined(SF_ENTRY_CG_START_PARTIALS)
/* cg_start's rows, partition by partition: the partial sums. */
void main() {
  uint S = sf_push.S;
  uint s = sf_sigma_point();
  uint p = sf_partition();
  uint begin, end;
  sf_partition_nodes(p, begin, end);
  if (s >= S) end = begin; /* a lane past the last sigma point: no rows, the group's barriers */
  real sum_bb, sum_rr, sum_rz;
  sf_start_rows(s, S, begin, end, sum_bb, sum_rr, sum_rz);
  if (s < S && sf_leads()) {
    partial[(SF_PARTIAL_BB * S + s) * SF_PARTITIONS + p] = sum_bb;
    partial[(SF_PARTIAL_RR * S + s) * SF_PARTITIONS + p] = sum_rr;
    partial[(SF_PARTIAL_RZ * S + s) * SF_PARTITIONS + p] = sum_rz;
  }
}

#  else /* SF_ENTRY_CG_START_SCALARS */
/* An invocation per sigma point: the sums of the partials, the scalars and every group's
 * copies. */
void main() {
  uint S = sf_push.S;
  uint s = gl_GlobalInvocationID.x;
  if (s >= S) return;
  real sum_bb, sum_rr, sum_rz;
  SF_PARTIALS_SUM(SF_PARTIAL_BB, S, s, sum_bb)
  SF_PARTIALS_SUM(SF_PARTIAL_RR, S, s, sum_rr)
  SF_PARTIALS_SUM(SF_PARTIAL_RZ, S, s, sum_rz)
  bool going = sf_start_scalars(s, sum_bb, sum_rr, sum_rz);
  for (uint p = 0u; p < SF_PARTITIONS; ++p) {
    own_active[s * SF_PARTITIONS + p] = going ? 1u : 0u;
    own_iterations[s * SF_PARTITIONS + p] = 0;
    own_rz[s * SF_PARTITIONS + p] = sum_rz;
  }
}
#  endif

#else /* the iteration's shaders: one descriptor set for the four */
SF_READ_REALS(SF_CG_ITERATION_CONSTANTS, c)
SF_READ_REALS(SF_CG_ITERATION_INVERSE_DIAGONAL, inverse_diagonal)
layout(std430, binding = SF_CG_ITERATION_DV) restrict buffer X { real x[]; };
layout(std430, binding = SF_CG_ITERATION_R) restrict buffer R { real r[]; };
layout(std430, binding = SF_CG_ITERATION_Z) restrict buffer Z { real z[]; };
layout(std430, binding = SF_CG_ITERATION_D) restrict buffer D { real d[]; };
#  if defined(SF_ENTRY_CG_NODE_ITERATION)
/* q is this shader's own (each work-item writes and reads its rows); the node rows' buffers
 * (node_rows.h) and the element outputs are read. */
#    include "node_rows.h"
layout(std430, binding = SF_CG_ITERATION_Q) restrict buffer Q { real q[]; };
#    define SF_Q(row) q[row]
SF_READ_INTS(SF_CG_ITERATION_INCIDENCE_OFFSETS, incidence_offsets)
SF_READ_INTS(SF_CG_ITERATION_INCIDENCE, incidence)
SF_READ_INTS(SF_CG_ITERATION_LIGAMENT_OFFSETS, ligament_offsets)
SF_READ_INTS(SF_CG_ITERATION_LIGAMENT_OF_NODE, ligament_of_node)
SF_READ_REALS(SF_CG_ITERATION_LIGAMENT_K, ligament_k)
SF_READ_REALS(SF_CG_ITERATION_CONTROL_K, control_k)
SF_READ_REALS(SF_CG_ITERATION_MASS, mass)
SF_READ_REALS(SF_CG_ITERATION_ELEMENT_OUT, element_out)
#  else
SF_READ_REALS(SF_CG_ITERATION_Q, q)
#    define SF_Q(row) SF_LOAD(q, row)
#  endif
SF_READ_REALS(SF_CG_ITERATION_BB, bb)
layout(std430, binding = SF_CG_ITERATION_RR) restrict buffer RR { real rr[]; };
layout(std430, binding = SF_CG_ITERATION_RZ) restrict buffer RZ { real rz[]; };
layout(std430, binding = SF_CG_ITERATION_ACTIVE) restrict buffer Active { uint active_flags[]; };
layout(std430, binding = SF_CG_ITERATION_CONVERGED) restrict buffer Converged { uint converged[]; };
layout(std430, binding = SF_CG_ITERATION_ITERATIONS) restrict buffer Iterations { int iterations[]; };
layout(std430, binding = SF_CG_ITERATION_PARTIAL) restrict buffer Partial { real partial[]; };
layout(std430, binding = SF_CG_ITERATION_OWN_ACTIVE) restrict buffer OwnActive { uint own_active[]; };
layout(std430, binding = SF_CG_ITERATION_OWN_ITERATIONS) restrict buffer OwnIterations { int own_iterations[]; };
layout(std430, binding = SF_CG_ITERATION_OWN_RZ) restrict buffer OwnRz { real own_rz[]; };

/* The group's d.q over nodes [begin, end) of sigma point s. */
real sf_dq_rows(uint s, uint S, uint begin, uint end) {
  real sum_dq = real(0);
  for (uint n = begin + sf_first_row(); n < end; n += sf_row_step()) {
#  if defined(SF_ENTRY_CG_NODE_ITERATION)
    /* q = A d at the node's rows, as node_product forms it, kept for the update. */
    real spring;
    SF_NODE_SPRING(ligament_offsets, ligament_of_node, ligament_k, control_k, n, s, S, spring)
    real m = sf_solver_mass(SF_LOAD(mass, n), spring);
    real Kd[3];
    SF_CORNER_SUMS(element_out, incidence_offsets, incidence, n, s, S, Kd)
#  endif
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
      real d_row = d[row];
#  if defined(SF_ENTRY_CG_NODE_ITERATION)
      real q_row = SF_SYSTEM_ROW(c, s, S, Kd[k], spring, m, d_row);
      q[row] = q_row;
#  else
      real q_row = SF_LOAD(q, row);
#  endif
      sum_dq += d_row * q_row;
    }
  }
  return sf_group_sum(sum_dq);
}

/* x += alpha d, r -= alpha q, z = M^-1 r over the nodes; the group's r.r and r.z (with the
 * factor no z, and r.z 0: factor_solve forms them). */
void sf_update_rows(uint s, uint S, uint begin, uint end, real alpha, out real sum_rr,
                    out real sum_rz) {
  sum_rr = real(0);
  sum_rz = real(0);
  for (uint n = begin + sf_first_row(); n < end; n += sf_row_step())
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
#  if defined(SF_FACTOR) /* z is factor_solve's */
      SF_CG_UPDATE_XR_ROW(row, alpha, SF_Q(row), x, r, d, sum_rr)
#  else
      SF_CG_UPDATE_ROW(row, alpha, SF_Q(row), x, r, z, d, inverse_diagonal, sum_rr, sum_rz)
#  endif
    }
  sum_rr = sf_group_sum(sum_rr);
  sum_rz = sf_group_sum(sum_rz);
}

/* d = z + beta d over the nodes. */
void sf_direction_rows(uint s, uint S, uint begin, uint end, real beta) {
  for (uint n = begin + sf_first_row(); n < end; n += sf_row_step())
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + s;
      d[row] = z[row] + beta * d[row];
    }
}

/* The stop test of cg_rows.h with sigma point s's |b|^2 and the push constants' cap. */
bool sf_done(uint s, real sum_rr) {
  return sf_cg_converged(sum_rr, SF_LOAD(c, SF_CG_TOLERANCE2), SF_LOAD(bb, s));
}
bool sf_stop(bool done, real sum_rr, int count) {
  return sf_cg_stops(done, sum_rr, count, sf_push.max_iterations);
}

/* Sigma point s's scalars after an iteration (read by the host and the other shaders); r.z
 * with the factor is factor_solve's. */
void sf_store_scalars(uint s, int count, real sum_rr, real sum_rz, bool done, bool stop) {
  iterations[s] = count;
  rr[s] = sum_rr;
#  if !defined(SF_FACTOR)
  rz[s] = sum_rz;
#  endif
  if (done) converged[s] = 1u;
  if (stop) active_flags[s] = 0u;
}

#  if defined(SF_ENTRY_CG_ITERATION) || defined(SF_ENTRY_CG_NODE_ITERATION)
/* alpha = rz / d.q, x += alpha d, r -= alpha q, z = M^-1 r, then the stop test and
 * d = z + beta d. */
void main() {
  uint S = sf_push.S;
  uint s = sf_sigma_point();
  if (s >= S || active_flags[s] == 0u) return; /* the same for the whole group: no barrier is left waiting */
  int count = iterations[s] + 1;
  real rz_old = rz[s];
  real alpha = rz_old / sf_dq_rows(s, S, 0u, sf_push.count);
  real sum_rr, sum_rz;
  sf_update_rows(s, S, 0u, sf_push.count, alpha, sum_rr, sum_rz);
  bool done = sf_done(s, sum_rr);
  bool stop = sf_stop(done, sum_rr, count);
  sf_scalars_read();
  if (sf_leads()) sf_store_scalars(s, count, sum_rr, sum_rz, done, stop);
#    if !defined(SF_FACTOR) /* else factor_solve's z, r.z and direction */
  if (stop) return;
  sf_direction_rows(s, S, 0u, sf_push.count, sum_rz / rz_old);
#    endif
}

#  elif defined(SF_ENTRY_CG_PRECONDITIONED) || defined(SF_ENTRY_CG_DOT) || defined(SF_ENTRY_CG_UPDATE) || \
    defined(SF_ENTRY_CG_DIRECTION)
/* The partitions' shaders: this lane's sigma point s, partition p, their copies' index s P + p
 * and the partition's nodes; `going` whether its sigma point iterates (with `start`, every one
 * that exists). A group over one sigma point returns at once when it does not (the same for
 * the whole group: no barrier is left waiting); lanes over sigma points skip their rows and
 * keep to the barriers. */
struct SfPart {
  uint s, p, own, begin, end;
  bool going;
};
SfPart sf_part(bool start) {
  SfPart at;
  at.s = sf_sigma_point();
  at.p = sf_partition();
  at.own = at.s * SF_PARTITIONS + at.p;
  at.going = at.s < sf_push.S && (start || own_active[at.own] != 0u);
  sf_partition_nodes(at.p, at.begin, at.end);
  if (!at.going) at.end = at.begin;
  return at;
}

#    if defined(SF_ENTRY_CG_PRECONDITIONED)
/* After the V-cycle's z = M^-1 r: the partition's r.z, and at the start d = z. */
void main() {
  uint S = sf_push.S;
  bool start = sf_push.p != 0u;
  SfPart at = sf_part(start);
  if (!SF_SIGMA_LANES && !at.going) return;
  real sum_rz = real(0);
  for (uint n = at.begin + sf_first_row(); n < at.end; n += sf_row_step())
    for (uint k = 0u; k < 3u; ++k) {
      uint row = (3u * n + k) * S + at.s;
      real z_row = z[row];
      sum_rz += r[row] * z_row;
      if (start) d[row] = z_row;
    }
  sum_rz = sf_group_sum(sum_rz);
  if (at.going && sf_leads()) partial[(SF_PARTIAL_RZ * S + at.s) * SF_PARTITIONS + at.p] = sum_rz;
}

#    elif defined(SF_ENTRY_CG_DOT)
/* The iteration's first part after q = A d: the partition's d.q. */
void main() {
  uint S = sf_push.S;
  SfPart at = sf_part(false);
  if (!SF_SIGMA_LANES && !at.going) return;
  real sum_dq = sf_dq_rows(at.s, S, at.begin, at.end);
  if (at.going && sf_leads()) partial[(SF_PARTIAL_DQ * S + at.s) * SF_PARTITIONS + at.p] = sum_dq;
}

#    elif defined(SF_ENTRY_CG_UPDATE)
/* The second part: alpha, the partition's x, r, z, and its r.r and r.z. */
void main() {
  uint S = sf_push.S;
  SfPart at = sf_part(false);
  if (!SF_SIGMA_LANES && !at.going) return;
  real alpha = real(0);
  if (at.going) {
    real sum_dq;
    SF_PARTIALS_SUM(SF_PARTIAL_DQ, S, at.s, sum_dq)
    alpha = own_rz[at.own] / sum_dq;
  }
  real sum_rr, sum_rz;
  sf_update_rows(at.s, S, at.begin, at.end, alpha, sum_rr, sum_rz);
  if (at.going && sf_leads()) {
    partial[(SF_PARTIAL_RR * S + at.s) * SF_PARTITIONS + at.p] = sum_rr;
    partial[(SF_PARTIAL_RZ * S + at.s) * SF_PARTITIONS + at.p] = sum_rz;
  }
}

#    else /* SF_ENTRY_CG_DIRECTION */
/* The third part: the stop test, the lane's copies (and partition 0's the scalars), and the
 * partition's d = z + beta d. */
void main() {
  uint S = sf_push.S;
  SfPart at = sf_part(false);
  if (!SF_SIGMA_LANES && !at.going) return;
  int count = 0;
  real rz_old = real(1), sum_rr = real(0), sum_rz = real(0);
  bool done = false, stop = true;
  if (at.going) {
    count = own_iterations[at.own] + 1;
    rz_old = own_rz[at.own];
    SF_PARTIALS_SUM(SF_PARTIAL_RR, S, at.s, sum_rr)
    SF_PARTIALS_SUM(SF_PARTIAL_RZ, S, at.s, sum_rz)
    done = sf_done(at.s, sum_rr);
    stop = sf_stop(done, sum_rr, count);
  }
  memoryBarrierBuffer();
  barrier(); /* everyone has read the old copies before they change */
  if (at.going && sf_leads()) {
    own_iterations[at.own] = count;
    own_rz[at.own] = sum_rz;
    if (stop) own_active[at.own] = 0u;
    if (at.p == 0u) sf_store_scalars(at.s, count, sum_rr, sum_rz, done, stop);
  }
  if (!stop) sf_direction_rows(at.s, S, at.begin, at.end, sum_rz / rz_old);
}
#    endif

#  else
#    error "conjugate_gradient.comp: define one of the SF_ENTRY_CG_* entry points"
#  endif
#endif
