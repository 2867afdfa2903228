// refine_uniform (host/mesh/mesh_refine.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <set>
#include <utility>
#include <vector>

#include "host/mesh/mesh.h"
#include "mesh/unit_tetrahedron.h"
#include "tests/mesh/mesh_test_support.h"

namespace sigmafem {
namespace {

// Volumes are sums of a few thousand products: exact up to rounding of that order.
constexpr double kVolumeRoundoff = 1e-12;

// Sum of |volume|: meaningful for a parent given with inverted elements too.
double total_absolute_volume(const Mesh& mesh) {
  double sum = 0.0;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) sum += std::abs(tetrahedron_volume(mesh, e));
  return sum;
}

std::set<std::pair<int, int>> edges_of(const Mesh& mesh) {
  std::set<std::pair<int, int>> edges;
  for (const auto& t : mesh.tetrahedra) {
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) edges.insert(std::minmax(t[i], t[j]));
    }
  }
  return edges;
}

// The properties every refinement must have, checked against its parent mesh.
void expect_valid_refinement(const Mesh& parent, const Mesh& child, const char* what) {
  const auto parent_edges = edges_of(parent);
  ASSERT_EQ(child.tetrahedron_count(), 8 * parent.tetrahedron_count()) << what;
  ASSERT_EQ(child.node_count(), parent.node_count() + static_cast<int>(parent_edges.size()))
      << what << ": one new node per edge";
  for (int i = 0; i < parent.node_count(); ++i) {
    ASSERT_EQ(child.nodes[i], parent.nodes[i]) << what << ": old node " << i << " moved";
  }
  for (int e = 0; e < parent.tetrahedron_count(); ++e) {
    double children = 0.0;
    for (int c = 8 * e; c < 8 * e + 8; ++c) {
      const double v = tetrahedron_volume(child, c);
      ASSERT_GT(v, 0.0) << what << ": child " << c << " of element " << e << " is inverted";
      children += v;
    }
    ASSERT_NEAR(children, std::abs(tetrahedron_volume(parent, e)),
                kVolumeRoundoff * std::abs(tetrahedron_volume(parent, e)))
        << what << ": the children of element " << e << " fill it";
  }
  EXPECT_NEAR(total_absolute_volume(child), total_absolute_volume(parent), kVolumeRoundoff * total_absolute_volume(parent))
      << what;
  // Conforming: a mismatch between neighbours would leave extra unmatched faces.
  const auto faces = boundary_faces(child);
  EXPECT_EQ(faces.size(), 4 * boundary_faces(parent).size()) << what;
  test::expect_closed_outward_surface(child, faces, what);
}

TEST(RefineUniform, OneTetrahedronIntoEightOfAnEighthEach) {
  const Mesh parent = unit_tetrahedron();
  const Mesh child = refine_uniform(parent);
  expect_valid_refinement(parent, child, "unit tetrahedron");
  std::set<std::array<double, 3>> midpoints;
  for (int i = 4; i < 10; ++i)
    midpoints.insert({child.nodes[i].x(), child.nodes[i].y(), child.nodes[i].z()});
  const std::set<std::array<double, 3>> expected = {{0.5, 0, 0},   {0, 0.5, 0},   {0, 0, 0.5},
                                                    {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  EXPECT_EQ(midpoints, expected);
  for (int c = 0; c < 8; ++c) EXPECT_DOUBLE_EQ(tetrahedron_volume(child, c), 1.0 / 48.0) << c;
}

TEST(RefineUniform, LiverRefinesConformingly) {
  const Mesh liver = read_mesh(test::liver_msh());
  const Mesh refined = refine_uniform(liver);
  expect_valid_refinement(liver, refined, "liver.msh");
  // SOURCE.md: 914 edges, 276 boundary faces on 140 boundary nodes; each boundary edge
  // (276 * 3 / 2 of them) adds one boundary node.
  EXPECT_EQ(refined.node_count(), 181 + 914);
  EXPECT_EQ(boundary_nodes(refined).size(), 140u + 276u * 3u / 2u);
  Mesh checked = refined;
  EXPECT_EQ(orient_and_check(checked, "refined liver").inverted_reordered, 0);
}

TEST(RefineUniform, TwiceStillValid) {
  const Mesh box = read_mesh(test::box_msh());
  const Mesh once = refine_uniform(box);
  expect_valid_refinement(box, once, "box once");
  expect_valid_refinement(once, refine_uniform(once), "box twice");
}

// Children 4..7 of each parent fill its octahedron and share one diagonal; it must be the
// shortest of the three (the other two join the ring nodes that share no child edge).
TEST(RefineUniform, OctahedronIsCutAlongItsShortestDiagonal) {
  Mesh stretched = unit_tetrahedron();
  stretched.nodes[3] = {0.2, 0.1, 3.0};  // tall: makes the diagonals clearly unequal
  const Mesh liver = read_mesh(test::liver_msh());
  for (const Mesh& parent : {stretched, liver}) {
    const Mesh child = refine_uniform(parent);
    for (int e = 0; e < parent.tetrahedron_count(); ++e) {
      std::vector<int> common(child.tetrahedra[8 * e + 4].begin(),
                              child.tetrahedra[8 * e + 4].end());
      std::set<int> ring;
      std::set<std::pair<int, int>> child_edges;
      for (int c = 8 * e + 4; c < 8 * e + 8; ++c) {
        auto t = child.tetrahedra[c];
        std::sort(t.begin(), t.end());
        std::vector<int> kept;
        std::sort(common.begin(), common.end());
        std::set_intersection(common.begin(), common.end(), t.begin(), t.end(),
                              std::back_inserter(kept));
        common = kept;
        ring.insert(t.begin(), t.end());
        for (int i = 0; i < 4; ++i) {
          for (int j = i + 1; j < 4; ++j) child_edges.insert({t[i], t[j]});
        }
      }
      ASSERT_EQ(common.size(), 2u) << "element " << e << ": the four children share a diagonal";
      ring.erase(common[0]);
      ring.erase(common[1]);
      ASSERT_EQ(ring.size(), 4u);
      const double diagonal = (child.nodes[common[0]] - child.nodes[common[1]]).norm();
      for (const int r : ring) {
        for (const int s : ring) {
          if (r < s && child_edges.count({r, s}) == 0) {
            EXPECT_LE(diagonal, (child.nodes[r] - child.nodes[s]).norm()) << "element " << e;
          }
        }
      }
    }
  }
}

TEST(RefineUniform, InvertedParentsGivePositiveChildren) {
  Mesh parent = read_mesh(test::liver_msh());
  for (int e = 0; e < parent.tetrahedron_count(); e += 3)
    std::swap(parent.tetrahedra[e][0], parent.tetrahedra[e][3]);
  expect_valid_refinement(parent, refine_uniform(parent), "liver with inverted elements");
}

}  // namespace
}  // namespace sigmafem
