// Gmsh reader (host/mesh/mesh_gmsh.cpp): what it accepts beyond the round trip in
// mesh_read_test.cpp, and that each malformed file gives an InputError naming the file, the
// line and the problem.
#include <gtest/gtest.h>

#include <string>

#include "host/mesh/mesh.h"
#include "tests/mesh/mesh_test_support.h"

namespace sigmafem {
namespace {

// One tetrahedron in Gmsh 2.2. Line numbers used below: 5 node count, 6-9 nodes,
// 10 $EndNodes, 12 element count, 13 the tetrahedron, 14 $EndElements.
const std::string kHeader22 = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n";
const std::string kNodes22 = "$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$EndNodes\n";
const std::string kElements22 = "$Elements\n1\n1 4 2 1 1 1 2 3 4\n$EndElements\n";

// One tetrahedron in Gmsh 4.1: line 5 block header, 6 node block, 7-10 tags, 11-14 xyz,
// 15 $EndNodes, 17 element header, 18 element block, 19 the tetrahedron.
const std::string kNodes41 =
    "$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n";
const std::string kElements41 = "$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n$EndElements\n";
const std::string kHeader41 = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";

void expect_gmsh_error(const std::string& content, const std::string& expected) {
  test::expect_read_error("bad.msh", content, expected);
}
using test::replace;

Mesh read_text(const std::string& content) {
  test::TempDir dir;
  return read_mesh(dir.write("good.msh", content));
}

TEST(GmshReader, MinimalFilesOfEachVersionRead) {
  for (const std::string& text :
       {kHeader22 + kNodes22 + kElements22, kHeader41 + kNodes41 + kElements41,
        replace(kHeader22, "2.2", "2.0") + kNodes22 + kElements22,
        std::string("$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n"
                    "$ELM\n1\n1 4 1 1 4 1 2 3 4\n$ENDELM\n")}) {
    const Mesh mesh = read_text(text);
    ASSERT_EQ(mesh.node_count(), 4) << text;
    ASSERT_EQ(mesh.tetrahedron_count(), 1) << text;
    EXPECT_EQ(mesh.tetrahedra[0], (std::array<int, 4>{0, 1, 2, 3}));
    EXPECT_EQ(mesh.nodes[3], Eigen::Vector3d(0, 0, 1));
  }
}

// Each tetrahedron's physical group becomes its label (regions by label, issue 19): 1.0's
// reg-phys, 2.x's first tag (0 without tags), 4.1's volume entity's first physical tag from
// $Entities (0 for a volume without one); refinement gives the children their parent's.
TEST(GmshReader, PhysicalGroupsBecomeLabels) {
  EXPECT_EQ(read_text(std::string("$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n"
                                  "$ELM\n1\n1 4 7 1 4 1 2 3 4\n$ENDELM\n")).labels,
            std::vector<int>{7});
  EXPECT_EQ(read_text(kHeader22 + kNodes22 + "$Elements\n1\n1 4 2 5 1 1 2 3 4\n$EndElements\n").labels,
            std::vector<int>{5});
  EXPECT_EQ(read_text(kHeader22 + kNodes22 + "$Elements\n1\n1 4 0 1 2 3 4\n$EndElements\n").labels,
            std::vector<int>{0});
  const std::string entities = "$Entities\n1 0 0 2\n1 0 0 0 0\n1 0 0 0 1 1 1 1 9 0\n2 0 0 0 1 1 1 0 0\n$EndEntities\n";
  EXPECT_EQ(read_text(kHeader41 + entities + kNodes41 + kElements41).labels, std::vector<int>{9});
  EXPECT_EQ(read_text(kHeader41 + entities + kNodes41 + replace(kElements41, "3 1 4 1", "3 2 4 1")).labels,
            std::vector<int>{0});
  EXPECT_EQ(read_text(kHeader41 + kNodes41 + kElements41).labels, std::vector<int>{0}) << "no $Entities";
  Mesh labelled = read_text(kHeader22 + kNodes22 + "$Elements\n1\n1 4 2 5 1 1 2 3 4\n$EndElements\n");
  EXPECT_EQ(refine_uniform(labelled).labels, std::vector<int>(8, 5));
}

TEST(GmshReader, UnusedNodesAreKeptSoIndicesStayThoseOfTheFile) {
  const Mesh mesh =
      read_text(kHeader22 + "$Nodes\n5\n1 0 0 0\n2 1 0 0\n50 9 9 9\n3 0 1 0\n4 0 0 1\n$EndNodes\n" +
                kElements22);
  ASSERT_EQ(mesh.node_count(), 5);
  EXPECT_EQ(mesh.nodes[2], Eigen::Vector3d(9, 9, 9));
  EXPECT_EQ(mesh.tetrahedra[0], (std::array<int, 4>{0, 1, 3, 4}));
}

TEST(GmshReader, UnknownNodeIdNamesLineElementAndNode) {
  const std::string message = test::read_error(
      "liver.msh",
      kHeader22 + kNodes22 + replace(kElements22, "1 4 2 1 1 1 2 3 4", "17 4 2 1 1 1 2 3 999"));
  EXPECT_NE(message.find("liver.msh: line 13: element 17 refers to node 999, which the file "
                         "does not define"),
            std::string::npos)
      << message;
  // In a triangle too: a broken reference is a broken file whatever the element type.
  expect_gmsh_error(
      kHeader22 + kNodes22 + "$Elements\n2\n5 2 0 1 2 7\n1 4 2 1 1 1 2 3 4\n$EndElements\n",
      "line 13: element 5 refers to node 7");
  expect_gmsh_error(kHeader41 + kNodes41 + replace(kElements41, "1 1 2 3 4", "1 1 2 3 0"),
               "line 19: element 1 refers to node 0");
}

TEST(GmshReader, NonNumericFieldsNameLineAndField) {
  expect_gmsh_error(kHeader22 + replace(kNodes22, "2 1 0 0", "2 1 abc 0") + kElements22,
               "line 7: expected a y coordinate, found \"abc\"");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "2 1 0 0", "2 nan 0 0") + kElements22,
               "line 7: expected an x coordinate, found \"nan\"");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "2 1 0 0", "2 1 0 1.5x") + kElements22,
               "line 7: expected a z coordinate, found \"1.5x\"");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "3 0 1 0", "3e0 0 1 0") + kElements22,
               "line 8: expected a node id, found \"3e0\"");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "$Nodes\n4", "$Nodes\nfour") + kElements22,
               "line 5: expected the number of nodes, found \"four\"");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "$Nodes\n4", "$Nodes\n99999999999") + kElements22,
               "line 5: expected the number of nodes between 0 and 2147483647");
}

TEST(GmshReader, LineNumbersCountWindowsLineEndsOnce) {
  std::string text = kHeader22 + replace(kNodes22, "2 1 0 0", "2 1 x 0") + kElements22;
  std::string crlf;
  for (const char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  expect_gmsh_error(crlf, "line 7: expected a y coordinate");
}

TEST(GmshReader, TruncatedFilesSayWhatWasExpected) {
  const std::string full = kHeader22 + kNodes22 + kElements22;
  expect_gmsh_error(full.substr(0, full.find("3 0 1 0")),
               "file ends after line 7 (truncated?): expected node line");
  expect_gmsh_error(kHeader22 + kNodes22 + "$Elements\n1\n1 4 2 1 1 1 2 3 4\n",
               "file ends after line 13 (truncated?): expected $EndElements to close $Elements");
  expect_gmsh_error(kHeader22 + kNodes22, "no $Elements section");
  expect_gmsh_error(kHeader22 + kElements22, "line 4: $Elements comes before the nodes section");
  expect_gmsh_error("$MeshFormat\n", "expected the format line");
  expect_gmsh_error(kHeader22 + "$PhysicalNames\n1\n3 1 \"organ\"\n" + kNodes22,
               "expected $EndPhysicalNames to close $PhysicalNames (opened on line 4)");
  expect_gmsh_error(kHeader41 + kNodes41.substr(0, kNodes41.find("0 1 0")),
               "file ends after line 12 (truncated?): expected node coordinates");
}

TEST(GmshReader, CountsThatDisagreeWithTheLinesAreErrors) {
  expect_gmsh_error(kHeader22 + replace(kNodes22, "$Nodes\n4", "$Nodes\n3") + kElements22,
               "line 9: expected $EndNodes to close $Nodes, found \"4 0 0 1\"");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "$Nodes\n4", "$Nodes\n5") + kElements22,
               "line 10: expected a node line \"id x y z\", found 1 fields");
  expect_gmsh_error(kHeader41 + replace(kNodes41, "1 4 1 4", "1 5 1 5") + kElements41,
               "the node blocks hold 4 nodes, the header said 5");
  expect_gmsh_error(kHeader41 + kNodes41 + replace(kElements41, "1 1 1 1", "1 2 1 2"),
               "the element blocks hold 1 elements, the header said 2");
  expect_gmsh_error(kHeader41 + replace(kNodes41, "3 1 0 4", "3 1 0 9") + kElements41,
               "line 6: expected the block's node count between 0 and 4, found 9");
  expect_gmsh_error(
      "$NOD\n4\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n$ENDNOD\n"
      "$ELM\n1\n1 4 1 1 5 1 2 3 4\n$ENDELM\n",
      "line 10: element 1 says it has 5 nodes, the line lists 4");
}

TEST(GmshReader, MalformedElementsAndNodes) {
  expect_gmsh_error(kHeader22 + kNodes22 + replace(kElements22, "1 4 2 1 1 1 2 3 4", "1 4 2 1 1 1 2 3"),
               "line 13: element 1 is a tetrahedron (type 4) but has 3 nodes, expected 4");
  expect_gmsh_error(kHeader22 + kNodes22 + replace(kElements22, "1 4 2 1 1 1 2 3 4", "1 4 9 1 2 3"),
               "line 13: element 1 says it has 9 tags, the line is shorter");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "3 0 1 0", "2 0 1 0") + kElements22,
               "line 8: node 2 is defined twice");
  expect_gmsh_error(kHeader22 + replace(kNodes22, "3 0 1 0", "3 0 1") + kElements22,
               "line 8: expected a node line \"id x y z\", found 3 fields");
  expect_gmsh_error(kHeader41 + replace(kNodes41, "3 1 0 4", "3 1 1 4") + kElements41,
               "line 11: expected 6 coordinates for a node of this block, found 3 fields");
  expect_gmsh_error(kHeader22 + "garbage here\n" + kNodes22 + kElements22,
               "line 4: expected a section header ($Name), found \"garbage here\"");
}

TEST(GmshReader, NoTetrahedraIsAnError) {
  expect_gmsh_error(kHeader22 + kNodes22 + "$Elements\n2\n1 2 0 1 2 3\n2 1 0 1 2\n$EndElements\n",
               "no tetrahedra (Gmsh element type 4): the file has 2 elements of other types");
  expect_gmsh_error(kHeader22 + kNodes22 + "$Elements\n0\n$EndElements\n", "no tetrahedra");
}

TEST(GmshReader, UnsupportedVersionsAndBinaryAreRefused) {
  for (const std::string version : {"3.0", "4", "4.0", "1.0", "5.1"}) {
    expect_gmsh_error(replace(kHeader22, "2.2", version) + kNodes22 + kElements22,
                 "line 2: Gmsh format version " + version + " is not supported");
  }
  expect_gmsh_error(replace(kHeader22, "2.2 0 8", "2.2 1 8") + kNodes22 + kElements22,
               "binary Gmsh files are not supported");
  expect_gmsh_error(replace(kHeader22, "2.2 0 8", "2.2 0") + kNodes22 + kElements22,
               "line 2: expected \"version file-type data-size\"");
  expect_gmsh_error("$Comments\nhello\n$EndComments\n" + kNodes22,
               "line 1: expected $MeshFormat or $NOD (a Gmsh file), found \"$Comments\"");
}

}  // namespace
}  // namespace sigmafem
