// VtkSeries (host/generator/vtk_series.h): each frame carries, per tetrahedron, its region
// and Young's modulus, so that ParaView shows a stiff inclusion where the truth has it.
#include "host/generator/vtk_series.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "host/mesh/mesh.h"
#include "host/model/model.h"
#include "temp_path.h"

namespace sigmafem {
namespace {

// The values of the DataArray named `name` in `text`, as written (space-separated).
std::vector<std::string> array_values(const std::string& text, const std::string& name) {
  const std::size_t at = text.find("Name=\"" + name + "\"");
  EXPECT_NE(at, std::string::npos) << name;
  if (at == std::string::npos) return {};
  const std::size_t begin = text.find('>', at) + 1, end = text.find("</DataArray>", begin);
  std::istringstream in(text.substr(begin, end - begin));
  std::vector<std::string> values;
  for (std::string v; in >> v;) values.push_back(v);
  return values;
}

TEST(VtkSeries, EachTetrahedronCarriesItsRegionAndModulus) {
  const Mesh mesh = read_mesh(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.msh");
  Material material;
  material.young_modulus = 5000;
  material.poisson_ratio = 0.45;
  material.density = 1000;
  Model model = make_model(mesh, material);
  model.regions.push_back({"inclusion", {1, 4}, 25000});
  model.regions.push_back({"soft", {2}, 2500});
  test::TempDir dir;
  VtkSeries series(model, {0}, dir.path(), "frames");
  Eigen::VectorXd x(3 * model.node_count());
  for (int i = 0; i < model.node_count(); ++i) x.segment<3>(3 * i) = model.rest_positions[i];
  series.write_frame(0.0, x);
  series.finish();
  std::ifstream in(std::filesystem::path(dir.path()) / "vtk" / "frames_000000.vtu");
  std::ostringstream text;
  text << in.rdbuf();
  const std::vector<std::string> region = array_values(text.str(), "region");
  const std::vector<std::string> modulus = array_values(text.str(), "young_modulus");
  ASSERT_EQ(static_cast<int>(region.size()), model.element_count());
  ASSERT_EQ(static_cast<int>(modulus.size()), model.element_count());
  EXPECT_EQ(region[0], "0");
  EXPECT_EQ(region[1], "1");
  EXPECT_EQ(region[2], "2");
  EXPECT_EQ(region[4], "1");
  EXPECT_EQ(std::stod(modulus[0]), 5000.0);
  EXPECT_EQ(std::stod(modulus[1]), 25000.0);
  EXPECT_EQ(std::stod(modulus[2]), 2500.0);
  EXPECT_NE(text.str().find("<CellData Scalars=\"region\">"), std::string::npos);
}

}  // namespace
}  // namespace sigmafem
