#include "host/generator/vtk_series.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "host/common/atomic_file.h"
#include "host/common/input_error.h"
#include "host/data/csv_format.h"

namespace sigmafem {
namespace fs = std::filesystem;

namespace {

void write_int_array(std::ostream& out, const char* name, const std::vector<int>& values) {
  out << "        <DataArray type=\"Int32\" Name=\"" << name << "\" format=\"ascii\">\n";
  for (int v : values) out << v << ' ';
  out << "\n        </DataArray>\n";
}

}  // namespace

VtkSeries::VtkSeries(const Model& model, std::vector<int> observed_nodes, std::string directory,
                     std::string name)
    : model_(model), directory_(std::move(directory)), name_(std::move(name)) {
  const int n = model.node_count();
  ligament_mark_.assign(n, 0);
  observed_mark_.assign(n, 0);
  control_mark_.assign(n, 0);
  for (std::size_t l = 0; l < model.ligaments.size(); ++l)
    for (int node : model.ligaments[l].nodes) ligament_mark_[node] = static_cast<int>(l) + 1;
  for (std::size_t k = 0; k < observed_nodes.size(); ++k)
    observed_mark_[observed_nodes[k]] = static_cast<int>(k) + 1;
  for (int node : model.control.nodes) control_mark_[node] = 1;
  region_mark_.assign(static_cast<std::size_t>(model.element_count()), 0);
  young_modulus_.assign(static_cast<std::size_t>(model.element_count()), model.material.young_modulus);
  for (std::size_t r = 0; r < model.regions.size(); ++r)
    for (int e : model.regions[r].elements) {
      region_mark_[static_cast<std::size_t>(e)] = static_cast<int>(r) + 1;
      young_modulus_[static_cast<std::size_t>(e)] = model.regions[r].young_modulus;
    }
  const fs::path frames = fs::path(directory_) / "vtk";
  std::error_code error;
  if (!fs::create_directories(frames, error) && error)
    throw InputError(frames.string() + ": cannot create folder: " + error.message());
}

void VtkSeries::write_frame(double t, const Eigen::VectorXd& x) {
  char file_name[64];
  std::snprintf(file_name, sizeof file_name, "%s_%06d.vtu", name_.c_str(),
                static_cast<int>(frames_.size()));
  AtomicFile file((fs::path(directory_) / "vtk" / file_name).string());
  std::ostream& out = file.stream();
  const int n = model_.node_count(), m = model_.element_count();
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <UnstructuredGrid>\n"
      << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << m << "\">\n"
      << "      <Points>\n"
      << "        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
  for (int i = 0; i < 3 * n; ++i) out << format_number(x[i]) << (i % 3 == 2 ? '\n' : ' ');
  out << "        </DataArray>\n      </Points>\n      <Cells>\n"
      << "        <DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">\n";
  for (const ElementRest& element : model_.elements)
    out << element.nodes[0] << ' ' << element.nodes[1] << ' ' << element.nodes[2] << ' '
        << element.nodes[3] << '\n';
  out << "        </DataArray>\n"
      << "        <DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">\n";
  for (int e = 1; e <= m; ++e) out << 4 * e << (e % 16 == 0 ? '\n' : ' ');
  out << "\n        </DataArray>\n"
      << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n";
  for (int e = 1; e <= m; ++e) out << "10" << (e % 32 == 0 ? '\n' : ' ');  // VTK_TETRA
  out << "\n        </DataArray>\n      </Cells>\n"
      << "      <PointData Vectors=\"displacement\">\n"
      << "        <DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" "
         "format=\"ascii\">\n";
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d u = x.segment<3>(3 * i) - model_.rest_positions[i];
    out << format_number(u[0]) << ' ' << format_number(u[1]) << ' ' << format_number(u[2]) << '\n';
  }
  out << "        </DataArray>\n";
  write_int_array(out, "ligament", ligament_mark_);
  write_int_array(out, "observed", observed_mark_);
  write_int_array(out, "control", control_mark_);
  out << "      </PointData>\n"
      << "      <CellData Scalars=\"region\">\n";
  write_int_array(out, "region", region_mark_);
  out << "        <DataArray type=\"Float64\" Name=\"young_modulus\" format=\"ascii\">\n";
  for (int e = 0; e < m; ++e) out << format_number(young_modulus_[static_cast<std::size_t>(e)]) << (e % 8 == 7 ? '\n' : ' ');
  out << "\n        </DataArray>\n      </CellData>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  file.commit();
  frames_.emplace_back(t, file_name);
}

void VtkSeries::finish() {
  std::ostringstream pvd;
  pvd << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (const auto& [t, file_name] : frames_)
    pvd << "    <DataSet timestep=\"" << format_number(t) << "\" group=\"\" part=\"0\" file=\"vtk/"
        << file_name << "\"/>\n";
  pvd << "  </Collection>\n</VTKFile>\n";
  write_file_atomically((fs::path(directory_) / (name_ + ".pvd")).string(), pvd.str());
}

}  // namespace sigmafem
