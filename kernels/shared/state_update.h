/* state_update.h: one row of one sigma point after the CG solve, v += dv, x += h v (the
 * state_update kernels of state_update.cl and .comp; host: ReferenceSimulation::step). A sigma
 * point whose right-hand side was zero (bb = 0) keeps dv = 0, CG's exact answer. `at` indexes
 * the per-dof buffers, `bb_s` is the sigma point's bb (in Vulkan's sigma-quad form, a lane's
 * four sigma points' row and their four bb: kernels/vulkan/sigma_quads.h). */
#ifndef SIGMAFEM_STATE_UPDATE_H
#define SIGMAFEM_STATE_UPDATE_H

#include "dialect.h"

#define SF_STATE_UPDATE_ROW(at, bb_s, h, dv, x, v)              \
  {                                                             \
    SF_REAL dv_ = SF_SELECT(SF_NONZERO(bb_s), dv[at], SF_LIT(0)); \
    dv[at] = dv_;                                               \
    SF_REAL velocity_ = v[at] + dv_;                            \
    v[at] = velocity_;                                          \
    x[at] += (h) * velocity_;                                   \
  }

#endif /* SIGMAFEM_STATE_UPDATE_H */
