// Legacy VTK reader (host/mesh/mesh_vtk.cpp): what it accepts beyond the round trip in
// mesh_read_test.cpp, and that each malformed file gives an InputError naming the file, and
// the line where there is one.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <sstream>
#include <string>

#include "host/mesh/mesh.h"
#include "tests/mesh/mesh_test_support.h"

namespace sigmafem {
namespace {

// One tetrahedron. Lines: 5 POINTS, 6-7 coordinates, 8 CELLS, 9 the cell, 10 CELL_TYPES.
const std::string kAscii =
    "# vtk DataFile Version 3.0\none tetrahedron\nASCII\nDATASET UNSTRUCTURED_GRID\n"
    "POINTS 4 float\n0 0 0 1 0 0\n0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n";

Mesh one_tetrahedron() {
  Mesh mesh;
  mesh.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.tetrahedra = {{0, 1, 2, 3}};
  return mesh;
}

void expect_vtk_error(const std::string& content, const std::string& expected) {
  test::expect_read_error("bad.vtk", content, expected);
}
using test::replace;

Mesh read_named(const std::string& name, const std::string& content) {
  test::TempDir dir;
  return read_mesh(dir.write(name, content));
}

TEST(VtkReader, MinimalAsciiFileReads) {
  test::TempDir dir;
  const Mesh mesh = read_mesh(dir.write("tet.vtk", kAscii));
  ASSERT_EQ(mesh.node_count(), 4);
  ASSERT_EQ(mesh.tetrahedron_count(), 1);
  EXPECT_EQ(mesh.tetrahedra[0], (std::array<int, 4>{0, 1, 2, 3}));
  EXPECT_EQ(mesh.nodes[3], Eigen::Vector3d(0, 0, 1));
  // Keywords are case-insensitive in VTK's own reader; so are they here.
  const Mesh lower = read_mesh(dir.write(
      "lower.vtk", replace(replace(kAscii, "POINTS", "points"), "CELL_TYPES", "cell_types")));
  EXPECT_EQ(lower.tetrahedron_count(), 1);
}

TEST(VtkReader, DatasetsOtherThanUnstructuredGridAreRefused) {
  expect_vtk_error(replace(kAscii, "UNSTRUCTURED_GRID", "POLYDATA"),
               "line 4: DATASET POLYDATA is not supported: sigmafem needs a volume mesh");
  expect_vtk_error(replace(kAscii, "ASCII", "TEXT"), "line 3: expected ASCII or BINARY on line 3");
  expect_vtk_error(replace(kAscii, "# vtk DataFile Version 3.0", "# vtk DataFile Version x"),
               "line 1: expected the VTK file version, found \"x\"");
}

TEST(VtkReader, CellsMustReferToExistingPoints) {
  expect_vtk_error(replace(kAscii, "4 0 1 2 3", "4 0 1 2 7"),
               "line 8: cell 0 refers to point 7, but POINTS (line 5) defines 4 points");
  expect_vtk_error(replace(kAscii, "4 0 1 2 3", "4 0 -1 2 3"), "cell 0 refers to point -1");
}

TEST(VtkReader, MalformedCellsAreErrors) {
  expect_vtk_error(replace(replace(kAscii, "CELLS 1 5", "CELLS 1 4"), "4 0 1 2 3", "3 0 1 2"),
               "line 8: cell 0 is a tetrahedron (type 10) but has 3 points, expected 4");
  expect_vtk_error(replace(kAscii, "4 0 1 2 3", "9 0 1 2 3"),
               "CELLS: cell 0 says it has 9 points, more than the list holds");
  expect_vtk_error(replace(replace(kAscii, "CELLS 1 5", "CELLS 1 6"), "4 0 1 2 3", "4 0 1 2 3 3"),
               "CELLS: the header says 6 values, the 1 cells use 5");
  expect_vtk_error(
      replace(replace(kAscii, "CELLS 1 5", "CELLS 2 5"), "CELL_TYPES 1\n10", "CELL_TYPES 2\n10 10"),
      "CELLS: the list of 5 values ends before cell 1");
  expect_vtk_error(replace(kAscii, "CELL_TYPES 1\n10", "CELL_TYPES 2\n10 10"),
               "line 10: CELL_TYPES lists 2 types for 1 cells");
  expect_vtk_error(replace(replace(replace(kAscii, "4 0 1 2 3", "3 0 1 2"), "CELLS 1 5", "CELLS 1 4"),
                       "CELL_TYPES 1\n10", "CELL_TYPES 1\n5"),
               "no tetrahedra (VTK cell type 10): the file has 1 cells of other types");
}

TEST(VtkReader, NumbersAndKeywordsAreChecked) {
  expect_vtk_error(replace(kAscii, "0 0 0 1 0 0", "0 0 0 1 x 0"),
               "line 6: expected POINTS coordinates, found \"x\"");
  expect_vtk_error(replace(kAscii, "POINTS 4 float", "POINTS 4 long"),
               "line 5: data type \"long\" is not supported");
  expect_vtk_error(replace(kAscii, "POINTS 4 float", "POINTS 4 int"),
               "POINTS must be float or double, found int");
  expect_vtk_error(replace(kAscii, "POINTS 4 float", "POINTS 99999999999 float"),
               "line 5: expected the number of points between 0 and 2147483647");
  expect_vtk_error(replace(kAscii, "CELL_TYPES", "POLYGONS"),
               "line 10: expected POINTS, CELLS or CELL_TYPES, found \"POLYGONS\"");
  expect_vtk_error(replace(kAscii, "CELLS 1 5\n4 0 1 2 3\n", ""), "no CELLS block");
}

TEST(VtkReader, TruncatedAsciiSaysWhere) {
  expect_vtk_error(kAscii.substr(0, kAscii.find("0 1 0 0 0 1")),
               "file ends after line 6 (truncated?): expected POINTS coordinates");
  expect_vtk_error(kAscii.substr(0, kAscii.find("DATASET")),
               "file ends after line 3 (truncated?): expected DATASET");
}

TEST(VtkReader, BinaryBlocksAreBoundsChecked) {
  const std::string binary = test::vtk_binary_text(one_tetrahedron());
  // Cut in the middle of the POINTS block (after the 6th of its 12 doubles).
  const std::size_t points = binary.find("POINTS 4 double\n") + 16;
  expect_vtk_error(binary.substr(0, points + 6 * 8),
               "(truncated?): expected 12 double values of POINTS coordinates");
  // A huge count must fail at once, not allocate for it.
  expect_vtk_error(replace(binary, "POINTS 4 double", "POINTS 2000000000 double"),
               "expected 6000000000 double values");
  expect_vtk_error(replace(binary, "POINTS 4 double", "POINTS 4 double extra"), "unexpected \"extra");
  // A NaN coordinate (big-endian quiet NaN 7ff8...).
  std::string nan = binary;
  nan[points] = '\x7f';
  nan[points + 1] = '\xf8';
  expect_vtk_error(nan, "POINTS coordinates: value 0 is not a finite number");
}

TEST(VtkReader, Version51OffsetsAreChecked) {
  const std::string ascii = test::vtk51_text(one_tetrahedron(), false);
  expect_vtk_error(replace(ascii, "OFFSETS vtktypeint64\n0\n4", "OFFSETS vtktypeint64\n1\n4"),
               "CELLS: OFFSETS must rise from 0 to the CONNECTIVITY size 4");
  expect_vtk_error(replace(ascii, "OFFSETS vtktypeint64", "OFFSETS float"),
               "expected an integer data type, found float");
  expect_vtk_error(replace(ascii, "CONNECTIVITY", "CONNECTIONS"),
               "expected CONNECTIVITY, found \"CONNECTIONS\"");
  // One cell, but its 64-bit connectivity names a point far outside the mesh.
  std::string binary = test::vtk51_text(one_tetrahedron(), true);
  const std::size_t connectivity = binary.find("CONNECTIVITY vtktypeint64\n") + 26;
  binary[connectivity] = '\x7f';
  expect_vtk_error(binary, "cell 0 refers to point 9151314442816847872");
}

// Labels (regions by label, issue 19): a one-component integer array of CELL_DATA, the
// tetrahedra's values only; "gmsh:physical" (meshio's name) before any other.
TEST(VtkReader, CellDataOfIntegersGivesTheTetrahedraLabels) {
  Mesh two = one_tetrahedron();
  two.tetrahedra.push_back({1, 0, 2, 3});
  two.labels = {4, 9};
  const Mesh ascii = read_named("labels.vtk", test::vtk_ascii_text(two));
  EXPECT_EQ(ascii.labels, (std::vector<int>{4, 9})) << "the vertex and the triangle (7) are no tetrahedra";
  EXPECT_EQ(ascii.labels_from, "CELL_DATA array \"region\" (line 22)");

  // meshio's Gmsh arrays in a FIELD, after POINT_DATA (skipped), geometrical first.
  const std::string cells = kAscii + "POINT_DATA 4\nVECTORS v float\n" + std::string(12 * 2, ' ') +
                            "0 0 0 0 0 0 0 0 0 0 0 0\nCELL_DATA 1\nSCALARS heat double\nLOOKUP_TABLE default\n0.5\n";
  const std::string field = "FIELD FieldData 2\ngmsh:geometrical 1 1 int\n3\ngmsh:physical 1 1 int\n12\n";
  EXPECT_EQ(read_named("field.vtk", cells + field).labels, std::vector<int>{12});
  EXPECT_TRUE(read_named("reals.vtk", cells).labels.empty()) << "a double array is no label";
  EXPECT_EQ(read_named("reals.vtk", cells).labels_from, "no one-component integer array in CELL_DATA");
  // No component count, no LOOKUP_TABLE (VTK's own reader allows both).
  EXPECT_EQ(read_named("bare.vtk", kAscii + "CELL_DATA 1\nSCALARS tag short\n-3\n").labels, std::vector<int>{-3});

  // BINARY: a big-endian int per cell, the triangle's first.
  std::string binary = test::vtk_binary_text(two) + "CELL_DATA 3\nSCALARS material int 1\nLOOKUP_TABLE default\n";
  std::ostringstream values;
  for (const std::int32_t v : {7, 4, 9}) test::put_big_endian(values, v);
  binary += values.str() + "\n";
  EXPECT_EQ(read_named("labels_binary.vtk", binary).labels, (std::vector<int>{4, 9}));
}

// The data sections never fail a mesh (it needs none of them): what stopped the reading, or
// why an array gives no labels, is kept for the scenario that asks for labels.
TEST(VtkReader, AnUnreadableDataSectionLeavesTheMeshWithoutLabelsAndSaysWhy) {
  const Mesh unknown_type = read_named("bits.vtk", kAscii + "CELL_DATA 1\nSCALARS flag bit 1\nLOOKUP_TABLE default\n1\n");
  EXPECT_EQ(unknown_type.tetrahedron_count(), 1);
  EXPECT_TRUE(unknown_type.labels.empty());
  EXPECT_EQ(unknown_type.labels_from.rfind("reading the data sections stopped: mesh ", 0), 0u) << unknown_type.labels_from;
  EXPECT_NE(unknown_type.labels_from.find("bits.vtk: line 13: data type \"bit\""),
            std::string::npos)
      << unknown_type.labels_from;
  const Mesh truncated = read_named("short.vtk", kAscii + "CELL_DATA 1\nSCALARS region int 1\nLOOKUP_TABLE default\n");
  EXPECT_NE(truncated.labels_from.find("(truncated?): expected CELL_DATA values"), std::string::npos) << truncated.labels_from;
  const Mesh miscounted = read_named("count.vtk", kAscii + "CELL_DATA 2\nSCALARS region int\n1 2\n");
  EXPECT_EQ(miscounted.labels_from, "CELL_DATA array \"region\" (line 13) has 2 values for 1 cells");
  const Mesh huge = read_named("huge.vtk", kAscii + "CELL_DATA 1\nSCALARS region vtktypeint64\n4294967296\n");
  EXPECT_NE(huge.labels_from.find("cell 0's value 4294967296 is not an int"), std::string::npos) << huge.labels_from;
  EXPECT_NE(read_named("junk.vtk", kAscii + "CELL_DATA 1\nCOLOURS x\n").labels_from.find(
                "expected a data attribute (SCALARS, FIELD, VECTORS, ...), found \"colours\""),
            std::string::npos);
}

}  // namespace
}  // namespace sigmafem
