// make_ensemble's report of the preconditioner each back end runs CG with (summary.json and
// report.json say it): the CPU back end's factors unless Jacobi is asked; Jacobi on the
// devices unless OpenCL is asked for its factor; Vulkan always Jacobi.
#include "host/engine/make_ensemble.h"

#include <gtest/gtest.h>

namespace sigmafem {
namespace {

DeviceOptions with(Preconditioner preconditioner) {
  DeviceOptions options;
  options.preconditioner = preconditioner;
  return options;
}

TEST(MakeEnsemble, SaysWhichPreconditionerEachBackEndRuns) {
  EXPECT_EQ(preconditioner_used("cpu", with(Preconditioner::automatic)), "factorised");
  EXPECT_EQ(preconditioner_used("cpu", with(Preconditioner::factorised)), "factorised");
  EXPECT_EQ(preconditioner_used("cpu", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(preconditioner_used("opencl", with(Preconditioner::automatic)), "jacobi");
  EXPECT_EQ(preconditioner_used("opencl", with(Preconditioner::factorised)), "factorised");
  EXPECT_EQ(preconditioner_used("opencl", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(preconditioner_used("vulkan", with(Preconditioner::automatic)), "jacobi");
}

}  // namespace
}  // namespace sigmafem
