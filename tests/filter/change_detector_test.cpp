// ChangeDetector on synthetic NIS sequences: each step's NIS is level x chi-square(m), the
// level 1 for a consistent model, above 1 for a persistent model error.
#include "filter/change_detector.h"

#include "filter/statistical_distributions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace sigmafem {
namespace {

constexpr int kRows = 36;   // the shipped liver's 12 observed points

// Feeds one step per level; returns the steps (0-based) at which the detector fired.
std::vector<int> feed(ChangeDetector& detector, const std::vector<double>& levels, unsigned seed) {
  std::mt19937 random(seed);
  std::chi_squared_distribution<double> chi_square(kRows);
  std::vector<int> fired;
  for (int k = 0; k < static_cast<int>(levels.size()); ++k)
    if (detector.update(levels[static_cast<std::size_t>(k)] * chi_square(random), kRows)) fired.push_back(k);
  return fired;
}

TEST(ChangeDetector, SilentOnAConsistentModel) {
  ChangeDetector detector{ChangeDetectorOptions{}};
  EXPECT_TRUE(feed(detector, std::vector<double>(20000, 1.0), 1).empty());
  EXPECT_GE(detector.reference_level(), 1.0);
  EXPECT_LT(detector.reference_level(), 1.5);
}

TEST(ChangeDetector, SilentOnAPersistentModelErrorThatDrifts) {
  // The level the liver's filter saw with the truth on a finer mesh: 1.3 to 2.2, varying over
  // hundreds of steps. The nominal test (level 1) fires on it: shown first.
  std::vector<double> levels;
  for (int k = 0; k < 3000; ++k) levels.push_back(1.75 + 0.45 * std::sin(k / 150.0));
  ChangeDetector detector{ChangeDetectorOptions{}};
  EXPECT_TRUE(feed(detector, levels, 2).empty());
  EXPECT_GT(detector.reference_level(), 1.2);
  const int window_rows = ChangeDetectorOptions{}.window * kRows;
  EXPECT_GT(1.75 * window_rows, chi_square_tail_quantile(ChangeDetectorOptions{}.false_alarm, window_rows))
      << "the mean level is within the nominal test's threshold: the case would not show the difference";
}

TEST(ChangeDetector, FiresOnAJumpOnTopOfAModelError) {
  // Level 1.5 (a model error), then a cut: the NIS jumps fourfold.
  std::vector<double> levels(500, 1.5);
  levels.resize(700, 6.0);
  ChangeDetector detector{ChangeDetectorOptions{}};
  const std::vector<int> fired = feed(detector, levels, 3);
  ASSERT_FALSE(fired.empty());
  EXPECT_GE(fired.front(), 500) << "fired before the jump";
  EXPECT_LT(fired.front(), 500 + ChangeDetectorOptions{}.window) << "fired late";
}

TEST(ChangeDetector, SettlesWhenTheLevelIsBackToTheOneBeforeTheFiring) {
  const ChangeDetectorOptions options;
  ChangeDetector detector{options};
  std::vector<double> levels(300, 1.5);
  levels.resize(310, 6.0);
  std::mt19937 random(4);
  std::chi_squared_distribution<double> chi_square(kRows);
  int fired_at = -1;
  for (int k = 0; k < static_cast<int>(levels.size()); ++k)
    if (detector.update(levels[static_cast<std::size_t>(k)] * chi_square(random), kRows)) fired_at = k;
  ASSERT_GE(fired_at, 300);
  // Still at the jumped level through the hold-off: not settled.
  for (int k = 0; k < options.hold_off; ++k) detector.update(6.0 * chi_square(random), kRows);
  EXPECT_FALSE(detector.settled());
  // Back to the level before the change (above the nominal 1): settled within a window.
  for (int k = 0; k < options.window; ++k) detector.update(1.5 * chi_square(random), kRows);
  EXPECT_TRUE(detector.settled()) << "a level of 1.5 was the model's before the change";
}

}  // namespace
}  // namespace sigmafem
