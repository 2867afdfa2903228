/* state_update.h: one row of one sigma point after the CG solve, v += dv, x += h v (the
 * state_update kernels of state_update.cl and .comp; host: ReferenceSimulation::step). A sigma
 * point whose right-hand side was zero (bb = 0) keeps dv = 0, CG's exact answer. `at` indexes
 * the per-dof buffers, `s` the per-sigma bb. */
#ifndef SIGMAFEM_STATE_UPDATE_H
#define SIGMAFEM_STATE_UPDATE_H

#include "dialect.h"

#define SF_STATE_UPDATE_ROW(at, s, h, bb, dv, x, v)      \
  {                                                      \
    if (SF_LOAD(bb, s) == SF_LIT(0)) dv[at] = SF_LIT(0); \
    SF_REAL velocity_ = v[at] + dv[at];                  \
    v[at] = velocity_;                                   \
    x[at] += (h) * velocity_;                            \
  }

#endif /* SIGMAFEM_STATE_UPDATE_H */
