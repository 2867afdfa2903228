// generate --truth-refine's spread springs (host/generator/spring_spread.h): each coarse node's
// part of a spring goes to the refined nodes of its shape function's support, and the parts
// add up to the spring's total.
#include "host/generator/spring_spread.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "host/scenario/scenario.h"
#include "scenario_directory.h"

namespace sigmafem {
namespace {


double total(const std::vector<SpringShare>& shares) {
  double sum = 0.0;
  for (const SpringShare& s : shares) sum += s.share;
  return sum;
}

TEST(SpringSpread, EveryPartStaysWithinTheCoarseNodesSupportAndThePartsSumToOne) {
  const Scenario scenario = load_scenario(kScenarios + "liver.json");
  const Mesh& coarse = scenario.mesh;
  const Mesh fine = refine_uniform(coarse);
  const std::vector<int> fine_boundary = boundary_nodes(fine);
  for (const Ligament& ligament : scenario.ligaments) {
    const std::vector<SpringShare> spread = spread_spring(coarse, ligament.nodes, fine);
    EXPECT_NEAR(total(spread), 1.0, 1e-12) << ligament.name;
    // One level: the coarse nodes themselves and midpoints of their edges, each on the surface
    // (the liver's ligament nodes lie on it, and so does what holds them).
    for (const SpringShare& s : spread) {
      EXPECT_GT(s.share, 0.0);
      EXPECT_TRUE(std::binary_search(fine_boundary.begin(), fine_boundary.end(), s.node)) << "node " << s.node;
      bool in_support = std::find(ligament.nodes.begin(), ligament.nodes.end(), s.node) != ligament.nodes.end();
      for (const std::array<int, 4>& t : coarse.tetrahedra)
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b)
            if (a != b && std::find(ligament.nodes.begin(), ligament.nodes.end(), t[a]) != ligament.nodes.end() &&
                (fine.nodes[static_cast<std::size_t>(s.node)] - 0.5 * (coarse.nodes[t[a]] + coarse.nodes[t[b]])).norm() < 1e-12)
              in_support = true;
      EXPECT_TRUE(in_support) << ligament.name << ": node " << s.node << " is neither a ligament node nor the midpoint of one of its edges";
    }
    // Each coarse node keeps a part, and more than a point: a patch of nodes holds it.
    for (int node : ligament.nodes)
      EXPECT_TRUE(std::any_of(spread.begin(), spread.end(), [node](const SpringShare& s) { return s.node == node; }));
    EXPECT_GT(spread.size(), 3 * ligament.nodes.size()) << ligament.name;
  }
}

TEST(SpringSpread, TheSameAttachmentAtEveryLevel) {
  // The part of each coarse node, and where its patch's weight lies, do not depend on the
  // level: the share-weighted centroid of a spring on the mesh refined twice is that on the
  // mesh refined once, within a small part of the patch's size.
  const Scenario scenario = load_scenario(kScenarios + "box.json");
  const Mesh& coarse = scenario.mesh;
  const Mesh once = refine_uniform(coarse);
  const Mesh twice = refine_uniform(once);
  for (const Ligament& ligament : scenario.ligaments) {
    auto centroid = [&](const Mesh& fine) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const SpringShare& s : spread_spring(coarse, ligament.nodes, fine)) c += s.share * fine.nodes[static_cast<std::size_t>(s.node)];
      return c;
    };
    Eigen::Vector3d nodes_centroid = Eigen::Vector3d::Zero();
    for (int node : ligament.nodes) nodes_centroid += coarse.nodes[static_cast<std::size_t>(node)] / static_cast<double>(ligament.nodes.size());
    const double moved_once = (centroid(once) - nodes_centroid).norm();
    const double between_levels = (centroid(twice) - centroid(once)).norm();
    EXPECT_LT(between_levels, 0.5 * moved_once + 1e-4) << ligament.name << ": " << between_levels << " m between levels";
  }
}

}  // namespace
}  // namespace sigmafem
