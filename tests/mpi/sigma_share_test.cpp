// sigma_share: every sigma point on exactly one rank, in rank order, shares within one.
#include "host/mpi/sigma_share.h"

#include <gtest/gtest.h>

namespace sigmafem {
namespace {

TEST(SigmaShare, EverySigmaPointIsOnOneRankInOrderAndSharesDifferByAtMostOne) {
  for (int S = 1; S <= 129; ++S)
    for (int R = 1; R <= S && R <= 70; ++R) {
      int next = 0, smallest = S, largest = 0;
      for (int r = 0; r < R; ++r) {
        const SigmaShare share = sigma_share(S, R, r);
        ASSERT_EQ(share.first, next) << "S " << S << ", R " << R << ", rank " << r;
        next += share.count;
        smallest = std::min(smallest, share.count);
        largest = std::max(largest, share.count);
      }
      ASSERT_EQ(next, S) << "S " << S << ", R " << R;
      ASSERT_GE(smallest, 1);
      ASSERT_LE(largest - smallest, 1);
    }
  EXPECT_EQ(sigma_share(17, 3, 2).first, 12);
  EXPECT_EQ(sigma_share(17, 3, 2).count, 5);
}

}  // namespace
}  // namespace sigmafem
