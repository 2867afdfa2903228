/* factor_solve: z = M^-1 r for CG with one sparse Cholesky factor shared by the sigma points
 * (M = P^T L L^T P, made on the host from the representative's system:
 * host/reference/factorised_preconditioner.h; host: host/vulkan/vulkan_factor_solve.cpp;
 * OpenCL's sf_block_factor_solve in conjugate_gradient.cl does the same on PoCL).
 *
 * A lane per sigma point (work-group g holds sigma points g G .. g G + G - 1, G the group
 * size, specialization constant 0): the substitutions are sequential along L's rows, while
 * the sigma points are independent, and L's entries are read once for the group at the same
 * address in every lane. Both substitutions read, never scatter: L y = P r by L's rows
 * (y_j = ((P r)_j - sum_k<j L_jk y_k) / L_jj) and L^T w = y by its columns (w_j = (y_j -
 * sum_k>j L_kj w_k) / L_jj), each w_j also stored as z at its original row. Between them,
 * the correction for the sigma point's own springs (SpringCorrection, host/reference/
 * spring_correction.h; OpenCL's SF_SPRING_ROWS): y -= V H_s V^T y at the rows V reaches, with
 * V^T y and H_s V^T y kept in y's rows n .. n + 2m - 1 (none where m = 0: no steps).
 *
 * llvmpipe ends every loop of an invocation, silently, once its loops together have turned
 * 65535 times (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS; bench/RESULTS.md, stop 52), and a
 * factor has far more entries than that beyond the smallest meshes. So the solve is a
 * sequence of steps, each a short loop, and one dispatch does a range of them, cut by the
 * host to a bound of loop turns (push constants: count = the first step, p = one past the
 * last; S the sigma points). The steps, with m spring rows reaching u rows of L:
 *   [0, n)                   the forward rows
 *   [n, n + m)               V^T y, a sum over the u rows each
 *   [n + m, n + 2m)          H_s V^T y, a sum over m each
 *   [n + 2m, n + 2m + u)     y -= V H_s V^T y at one reached row each
 *   [n + 2m + u, 2n + 2m + u)  the backward columns, from the last.
 * An inactive sigma point (CG done) is left alone.
 *
 * The work vector y ([row S + s], in L's order) is a storage texel buffer in float32: llvmpipe
 * loads a storage buffer at lane-varying addresses one lane at a time, an image in one gather
 * (the liver's solve at S = 4 1.02 -> 0.70 ms; bench/RESULTS.md, stop 53). */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"

layout(local_size_x_id = 0) in;
/* n, the rows of L (3 x nodes), set at pipeline creation. */
layout(constant_id = 1) const uint SF_FACTOR_ROWS = 1u;

SF_READ_INTS(SF_FACTOR_SOLVE_ROW_STARTS, row_starts)
SF_READ_INTS(SF_FACTOR_SOLVE_ROW_COLUMNS, row_columns)
SF_READ_REALS(SF_FACTOR_SOLVE_ROW_VALUES, row_values)
SF_READ_INTS(SF_FACTOR_SOLVE_COLUMN_STARTS, column_starts)
SF_READ_INTS(SF_FACTOR_SOLVE_COLUMN_ROWS, column_rows)
SF_READ_REALS(SF_FACTOR_SOLVE_COLUMN_VALUES, column_values)
SF_READ_INTS(SF_FACTOR_SOLVE_ORIGINAL_ROW, original_row)
SF_READ_REALS(SF_FACTOR_SOLVE_R, r)
layout(std430, binding = SF_FACTOR_SOLVE_Z) restrict writeonly buffer Z { real z[]; };
SF_READ_UINTS(SF_FACTOR_SOLVE_ACTIVE, active_flags)
SF_READ_INTS(SF_FACTOR_SOLVE_SPRING_AT, spring_at)
SF_READ_REALS(SF_FACTOR_SOLVE_SPRING_SOLVES, spring_solves)
SF_READ_REALS(SF_FACTOR_SOLVE_SPRING_COUPLING, spring_coupling)
#if defined(SF_USE_DOUBLE)
layout(std430, binding = SF_FACTOR_SOLVE_WORK) restrict buffer Work { real y[]; };
#  define SF_Y(i) y[i]
#  define SF_SET_Y(i, value) y[i] = (value)
#else
layout(binding = SF_FACTOR_SOLVE_WORK, r32f) uniform restrict imageBuffer y;
#  define SF_Y(i) imageLoad(y, int(i)).x
#  define SF_SET_Y(i, value) imageStore(y, int(i), vec4(value))
#endif

void main() {
  uint S = sf_push.S;
  uint s = gl_WorkGroupID.x * gl_WorkGroupSize.x + gl_LocalInvocationID.x;
  if (s >= S || SF_LOAD(active_flags, s) == 0u) return;
  uint n = SF_FACTOR_ROWS;
  uint m = uint(SF_LOAD(spring_at, 0)), reached = uint(SF_LOAD(spring_at, 1));
  uint projected = n, coupled = n + m, updated = n + 2u * m, backward = n + 2u * m + reached;
  uint first = sf_push.count, last = sf_push.p;
  for (uint j = first; j < min(last, projected); ++j) { /* L y = P r: row j, its diagonal last */
    int begin = SF_LOAD(row_starts, j), end = SF_LOAD(row_starts, j + 1u) - 1;
    real sum = real(0);
    for (int k = begin; k < end; ++k)
      sum += SF_LOAD(row_values, k) * SF_Y(uint(SF_LOAD(row_columns, k)) * S + s);
    real b = SF_LOAD(r, uint(SF_LOAD(original_row, j)) * S + s);
    SF_SET_Y(j * S + s, (b - sum) / SF_LOAD(row_values, end));
  }
  /* The springs' correction, each sum in a register (no arrays of m per lane). */
  for (uint step = max(first, projected); step < min(last, coupled); ++step) { /* (V^T y)_j */
    uint j = step - projected;
    real sum = real(0);
    for (uint u = 0u; u < reached; ++u)
      sum += SF_LOAD(spring_solves, u * m + j) * SF_Y(uint(SF_LOAD(spring_at, 2u + u)) * S + s);
    SF_SET_Y(step * S + s, sum);
  }
  for (uint step = max(first, coupled); step < min(last, updated); ++step) { /* (H_s V^T y)_j */
    uint j = step - coupled;
    real sum = real(0);
    for (uint k = 0u; k < m; ++k)
      sum += SF_LOAD(spring_coupling, (s * m + j) * m + k) * SF_Y((projected + k) * S + s);
    SF_SET_Y(step * S + s, sum);
  }
  for (uint step = max(first, updated); step < min(last, backward); ++step) { /* y -= V H_s V^T y */
    uint u = step - updated;
    uint at = uint(SF_LOAD(spring_at, 2u + u)) * S + s;
    real sum = real(0);
    for (uint j = 0u; j < m; ++j) sum += SF_LOAD(spring_solves, u * m + j) * SF_Y((coupled + j) * S + s);
    SF_SET_Y(at, SF_Y(at) - sum);
  }
  for (uint step = max(first, backward); step < last; ++step) { /* L^T w = y: column j, diagonal first */
    uint j = backward + n - 1u - step;
    int begin = SF_LOAD(column_starts, j), end = SF_LOAD(column_starts, j + 1u);
    real sum = real(0);
    for (int k = begin + 1; k < end; ++k)
      sum += SF_LOAD(column_values, k) * SF_Y(uint(SF_LOAD(column_rows, k)) * S + s);
    real w = (SF_Y(j * S + s) - sum) / SF_LOAD(column_values, begin);
    SF_SET_Y(j * S + s, w);
    z[uint(SF_LOAD(original_row, j)) * S + s] = w;
  }
}
