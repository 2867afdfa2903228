/* multigrid: NestedMultigrid's V-cycle (host/reference/nested_multigrid.h) for every sigma
 * point at once, CG's preconditioner in Vulkan's GPU form where the mesh is a refinement: a
 * work-item per (row, sigma point), the rows of kernels/shared/multigrid_rows.h (OpenCL's
 * multigrid.cl runs the same). One source, three entry points:
 *   -DSF_ENTRY_MG_SMOOTH    mg_smooth:   a Chebyshev step of a level's smoothing
 *   -DSF_ENTRY_MG_RESIDUAL  mg_residual: r = b - A x
 *   -DSF_ENTRY_MG_PRODUCT   mg_product:  y = M x or y += M x (restriction, prolongation,
 *                                        the coarsest inverse)
 * Bindings SF_MG_* and the push constants' use: kernels/shared/device_layout.h. The host's
 * VulkanMultigrid (host/vulkan/vulkan_multigrid.cpp) records them level by level. */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"
#include "multigrid_rows.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
SF_READ_INTS(SF_MG_ROW_START, row_start)
SF_READ_INTS(SF_MG_COLUMNS, columns)
SF_READ_REALS(SF_MG_VALUES, values)
layout(std430, binding = SF_MG_IN) restrict readonly buffer In { real b[]; };
#if defined(SF_ENTRY_MG_PRODUCT)
layout(std430, binding = SF_MG_OUT) restrict buffer Out { real y[]; };
#else
layout(std430, binding = SF_MG_SHIFT) restrict readonly buffer Shift { real shift[]; };
layout(std430, binding = SF_MG_X) restrict readonly buffer X { real x_in[]; };
#  if defined(SF_ENTRY_MG_SMOOTH)
SF_READ_REALS(SF_MG_DIAGONAL, diagonal)
SF_READ_REALS(SF_MG_STEPS, steps)
layout(std430, binding = SF_MG_P) restrict readonly buffer P { real p_in[]; };
layout(std430, binding = SF_MG_OUT) restrict writeonly buffer XOut { real x_out[]; };
layout(std430, binding = SF_MG_P_OUT) restrict writeonly buffer POut { real p_out[]; };
#  else
layout(std430, binding = SF_MG_OUT) restrict writeonly buffer R { real r[]; };
#  endif
#endif

void main() {
  uint S = sf_push.S;
  uint at = sf_global_id();
  if (at >= sf_push.count * S) return;
  uint row = at / S, s = at % S;
  uint flags = sf_push.p;
#if defined(SF_ENTRY_MG_PRODUCT)
  SF_MG_PRODUCT_ROW(at, row, s, S, (flags & SF_MG_ACCUMULATE) != 0u, row_start, columns, values, b, y)
#else
  real own = (flags & SF_MG_SHIFTED) != 0u ? shift[at] : real(0);
#  if defined(SF_ENTRY_MG_SMOOTH)
  uint k = uint(sf_push.max_iterations);
  SF_MG_SMOOTH_ROW(at, row, s, S, k, (flags & SF_MG_FROM_ZERO) != 0u, own, row_start, columns, values,
                   diagonal, steps, b, x_in, p_in, x_out, p_out)
#  else
  SF_MG_RESIDUAL_ROW(at, row, s, S, own, row_start, columns, values, b, x_in, r)
#  endif
#endif
}
