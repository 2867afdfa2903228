// Tests for the Scenario queries (host/scenario/scenario.cpp): ligament lookup by name and
// the stiffness in effect at a time, before, at and after events.
#include "host/scenario/scenario.h"

#include <gtest/gtest.h>

namespace sigmafem {
namespace {

// Three ligaments and events as load_scenario() leaves them: sorted by time, equal times
// in file order.
Scenario three_ligaments() {
  Scenario s;
  s.ligaments = {{"corner_a", {0}, 150.0}, {"middle", {1}, 300.0}, {"corner_b", {2}, 200.0}};
  s.events = {{7.5, 1, "middle", 0.01}, {10.0, 0, "corner_a", 50.0}, {10.0, 0, "corner_a", 60.0}};
  return s;
}

TEST(ScenarioTest, LigamentIndexFindsByNameAndSaysMinusOneOtherwise) {
  const Scenario s = three_ligaments();
  EXPECT_EQ(s.ligament_index("corner_a"), 0);
  EXPECT_EQ(s.ligament_index("middle"), 1);
  EXPECT_EQ(s.ligament_index("corner_b"), 2);
  EXPECT_EQ(s.ligament_index("Middle"), -1) << "names are case-sensitive";
  EXPECT_EQ(s.ligament_index(""), -1);
}

TEST(ScenarioTest, StiffnessBeforeTheFirstEventIsTheLigamentsOwn) {
  const Scenario s = three_ligaments();
  EXPECT_EQ(s.ligament_stiffness_at(0.0), (std::vector<double>{150.0, 300.0, 200.0}));
  EXPECT_EQ(s.ligament_stiffness_at(7.49), (std::vector<double>{150.0, 300.0, 200.0}));
}

TEST(ScenarioTest, AnEventAppliesFromItsTimeOn) {
  const Scenario s = three_ligaments();
  EXPECT_EQ(s.ligament_stiffness_at(7.5), (std::vector<double>{150.0, 0.01, 200.0}));
  EXPECT_EQ(s.ligament_stiffness_at(9.99), (std::vector<double>{150.0, 0.01, 200.0}));
}

TEST(ScenarioTest, EventTimeComputedAsStepTimesDtLandsOnItsStep) {
  const Scenario s = three_ligaments();
  const double t = 750 * 0.01;  // 7.4999999999999991 in binary, one ulp short of 7.5
  EXPECT_EQ(s.ligament_stiffness_at(t)[1], 0.01) << "the 1e-9 s slack must catch step 750";
  EXPECT_EQ(s.ligament_stiffness_at(7.5 - 1e-6)[1], 300.0) << "the slack must stay tiny";
}

TEST(ScenarioTest, EventsAtTheSameTimeApplyInOrderTheLastWins) {
  const Scenario s = three_ligaments();
  EXPECT_EQ(s.ligament_stiffness_at(10.0), (std::vector<double>{60.0, 0.01, 200.0}));
  EXPECT_EQ(s.ligament_stiffness_at(1e6), (std::vector<double>{60.0, 0.01, 200.0}));
}

TEST(ScenarioTest, NoLigamentsGiveAnEmptyList) {
  EXPECT_TRUE(Scenario().ligament_stiffness_at(3.0).empty());
}

}  // namespace
}  // namespace sigmafem
