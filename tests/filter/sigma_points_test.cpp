// The sigma-point sets: the identities the ROUKF relies on (docs/ROUKF.md).
#include "filter/sigma_points.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

namespace sigmafem {
namespace {

// The identities are exact algebra; 1e-12 leaves room only for rounding.
constexpr double kRounding = 1e-12;

class SigmaPointsTest : public ::testing::TestWithParam<SigmaPointSet> {};

TEST_P(SigmaPointsTest, DirectionsSumToZeroWithIdentityCovariance) {
  for (int p = 1; p <= 8; ++p) {
    const SigmaPoints points = make_sigma_points(GetParam(), p);
    const int expected = GetParam() == SigmaPointSet::simplex ? p + 1 : 2 * p + 1;
    ASSERT_EQ(points.count(), expected) << to_string(GetParam()) << " p=" << p;
    EXPECT_EQ(sigma_point_count(GetParam(), p), expected) << to_string(GetParam()) << " p=" << p;
    EXPECT_NEAR(points.alpha * points.count(), 1.0, kRounding) << "weights sum to one";
    const Eigen::VectorXd sum = points.directions.rowwise().sum();
    EXPECT_LT(sum.norm(), kRounding) << to_string(GetParam()) << " p=" << p << ": sum V_i";
    const Eigen::MatrixXd covariance =
        points.alpha * points.directions * points.directions.transpose();
    EXPECT_LT((covariance - Eigen::MatrixXd::Identity(p, p)).norm(), kRounding)
        << to_string(GetParam()) << " p=" << p << ": alpha sum V_i V_i^T";
  }
}

TEST_P(SigmaPointsTest, RejectsZeroParameters) {
  EXPECT_THROW(make_sigma_points(GetParam(), 0), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(BothSets, SigmaPointsTest,
                         ::testing::Values(SigmaPointSet::simplex, SigmaPointSet::star),
                         [](const auto& param_info) { return std::string(to_string(param_info.param)); });

TEST(SigmaPointSetNames, ParseAndPrint) {
  EXPECT_EQ(parse_sigma_point_set("simplex"), SigmaPointSet::simplex);
  EXPECT_EQ(parse_sigma_point_set("star"), SigmaPointSet::star);
  EXPECT_THROW(parse_sigma_point_set("cube"), std::invalid_argument);
}

}  // namespace
}  // namespace sigmafem
