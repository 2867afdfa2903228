// Test geometry for the physics tests (tests/reference/): a structured box of tetrahedra built
// in code, so that these tests depend on no mesh file and no mesh reader; random rotations
// and vectors for the rigid-motion checks; and the small spring-held box model the dynamic
// tests share. Header-only: the test build compiles only *_test.cpp files.
//
// The box [0,Lx] x [0,Ly] x [0,Lz] is cut into nx * ny * nz hexahedra of equal size and each
// hexahedron into the six Kuhn (Freudenthal) tetrahedra around its main diagonal (0,0,0)-(1,1,1):
// tetrahedron pi walks from corner 000 to corner 111 adding one axis step at a time in the
// order of the permutation pi. Every hexahedron uses the same diagonal direction, so the
// face diagonals of neighbours agree and the mesh is conforming. Odd permutations give a
// negative determinant; two corners are swapped there so every tetrahedron is positively
// oriented (mesh.h).
//
// Node (i, j, k), 0 <= i <= nx etc., has index i + (nx + 1) * (j + (ny + 1) * k).
// Optional jitter moves the interior nodes only (boundary nodes stay on the box faces, so
// the faces stay planar and the box's volume is exact), by a uniform random offset of at most
// `jitter` times the hexahedron's edge along each axis, from a fixed seed.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/mesh/mesh.h"
#include "host/model/model.h"

namespace sigmafem::test {

struct StructuredBox {
  Mesh mesh;
  Eigen::Vector3d size = Eigen::Vector3d::Ones();   // Lx, Ly, Lz, metres
  std::array<int, 3> cells{{1, 1, 1}};              // nx, ny, nz
  std::vector<std::array<int, 3>> grid;             // (i, j, k) of every node

  Eigen::Vector3d spacing() const {
    return {size[0] / cells[0], size[1] / cells[1], size[2] / cells[2]};
  }
  int node_index(int i, int j, int k) const {
    return i + (cells[0] + 1) * (j + (cells[1] + 1) * k);
  }
  // Whether node n lies on the box face axis = 0 (side 0) or axis = L (side 1).
  bool on_face(int n, int axis, int side) const {
    return grid[n][axis] == (side == 0 ? 0 : cells[axis]);
  }
  bool on_boundary(int n) const {
    for (int axis = 0; axis < 3; ++axis)
      if (on_face(n, axis, 0) || on_face(n, axis, 1)) return true;
    return false;
  }
  // The triangles of the tetrahedra that lie in one box face (found from the tetrahedra
  // themselves, whatever diagonal each face quad was cut along), as node triples.
  std::vector<std::array<int, 3>> face_triangles(int axis, int side) const {
    static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
    std::vector<std::array<int, 3>> triangles;
    for (const auto& tet : mesh.tetrahedra) {
      for (const auto& face : kFaces) {
        const std::array<int, 3> tri{{tet[face[0]], tet[face[1]], tet[face[2]]}};
        if (on_face(tri[0], axis, side) && on_face(tri[1], axis, side) &&
            on_face(tri[2], axis, side))
          triangles.push_back(tri);
      }
    }
    return triangles;
  }
  // Consistent nodal forces (flat, node-major) of a uniform traction t (N/m^2) on one face:
  // for linear triangles, each corner takes a third of the triangle's area times t.
  Eigen::VectorXd face_load(int axis, int side, const Eigen::Vector3d& traction) const {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * mesh.node_count());
    for (const auto& tri : face_triangles(axis, side)) {
      const Eigen::Vector3d& a = mesh.nodes[tri[0]];
      const double area =
          0.5 * (mesh.nodes[tri[1]] - a).cross(mesh.nodes[tri[2]] - a).norm();
      for (int node : tri) f.segment<3>(3 * node) += traction * (area / 3.0);
    }
    return f;
  }
};

inline double signed_volume(const Mesh& mesh, const std::array<int, 4>& tet) {
  const Eigen::Vector3d& a = mesh.nodes[tet[0]];
  return (mesh.nodes[tet[1]] - a).cross(mesh.nodes[tet[2]] - a).dot(mesh.nodes[tet[3]] - a) / 6.0;
}

// The box described in the file comment. `jitter` is a fraction of the edge, in [0, 0.15]:
// the Kuhn tetrahedra's smallest height is h / sqrt(2), so offsets up to 0.15 h per axis keep
// every tetrahedron well shaped; the helper checks it anyway and throws if not.
inline StructuredBox structured_box(const Eigen::Vector3d& size, int nx, int ny, int nz,
                                    double jitter = 0.0, unsigned seed = 20261101u) {
  if (nx < 1 || ny < 1 || nz < 1 || jitter < 0.0 || jitter > 0.15)
    throw std::invalid_argument("structured_box: need nx, ny, nz >= 1 and jitter in [0, 0.15]");
  StructuredBox box;
  box.size = size;
  box.cells = {{nx, ny, nz}};
  const Eigen::Vector3d h = box.spacing();
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> offset(-jitter, jitter);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i) {
        box.grid.push_back({{i, j, k}});
        box.mesh.nodes.emplace_back(i * h[0], j * h[1], k * h[2]);
      }
  if (jitter > 0.0) {
    for (int n = 0; n < box.mesh.node_count(); ++n) {
      if (box.on_boundary(n)) continue;
      for (int axis = 0; axis < 3; ++axis) box.mesh.nodes[n][axis] += offset(random) * h[axis];
    }
  }
  // The six permutations of the axes; even ones first.
  static constexpr int kPermutations[6][3] = {{0, 1, 2}, {1, 2, 0}, {2, 0, 1},
                                              {0, 2, 1}, {2, 1, 0}, {1, 0, 2}};
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (int p = 0; p < 6; ++p) {
          std::array<int, 3> corner{{i, j, k}};
          std::array<int, 4> tet{};
          tet[0] = box.node_index(corner[0], corner[1], corner[2]);
          for (int step = 0; step < 3; ++step) {
            ++corner[kPermutations[p][step]];
            tet[step + 1] = box.node_index(corner[0], corner[1], corner[2]);
          }
          if (p >= 3) std::swap(tet[2], tet[3]);   // odd permutation: restore orientation
          box.mesh.tetrahedra.push_back(tet);
        }
  // A Kuhn tetrahedron of the unjittered grid has volume hx hy hz / 6; jitter may shrink it,
  // but not below a quarter of that with the offsets allowed above.
  const double unjittered_volume = h[0] * h[1] * h[2] / 6.0;
  for (int e = 0; e < box.mesh.tetrahedron_count(); ++e) {
    const double volume = signed_volume(box.mesh, box.mesh.tetrahedra[e]);
    if (!(volume > 0.25 * unjittered_volume))
      throw std::logic_error("structured_box: tetrahedron " + std::to_string(e) +
                             " has volume " + std::to_string(volume) + ", expected about " +
                             std::to_string(unjittered_volume));
  }
  return box;
}

constexpr double kPi = 3.14159265358979323846;
constexpr double degrees(double angle) { return angle * kPi / 180.0; }

// A rotation drawn uniformly from SO(3) (a normalised Gaussian quaternion).
inline Eigen::Matrix3d random_rotation(std::mt19937& random) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(normal(random), normal(random), normal(random), normal(random));
  return q.normalized().toRotationMatrix();
}

// A vector of n entries uniform in [-scale, scale].
inline Eigen::VectorXd random_vector(std::mt19937& random, Eigen::Index n, double scale = 1.0) {
  std::uniform_real_distribution<double> uniform(-scale, scale);
  Eigen::VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v[i] = uniform(random);
  return v;
}

// The rotation by `angle` (radians) about `axis` (need not be unit length).
inline Eigen::Matrix3d rotation_about(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

// Rest positions of a mesh as one flat, node-major vector (corotational.h).
inline Eigen::VectorXd flat_positions(const Mesh& mesh) {
  Eigen::VectorXd x(3 * mesh.node_count());
  for (int n = 0; n < mesh.node_count(); ++n) x.segment<3>(3 * n) = mesh.nodes[n];
  return x;
}

// Q x + t for every node of a flat position vector.
inline Eigen::VectorXd rigidly_moved(const Eigen::VectorXd& x, const Eigen::Matrix3d& Q,
                                     const Eigen::Vector3d& t) {
  Eigen::VectorXd y(x.size());
  for (Eigen::Index n = 0; n < x.size() / 3; ++n) y.segment<3>(3 * n) = Q * x.segment<3>(3 * n) + t;
  return y;
}

// The dynamic tests' organ: a soft box (E 3 kPa, nu 0.45, 1000 kg/m^3, like liver tissue)
// 0.1 x 0.06 x 0.04 m in 5 x 3 x 2 jittered hexahedra, held by a ligament on its x = 0 face
// (100 N/m), pulled by a control spring on its x = 0.1 face (50 N/m) towards an SO that
// starts at the centroid of those nodes; gravity -9.81 m/s^2 along z, Rayleigh damping
// a = 0.01 s, b = 0.5 1/s, dt = 10 ms. The springs make the implicit Euler matrix SPD with
// a margin and the motion nontrivial (sag, pull and rotation).
struct HeldBox {
  StructuredBox box;
  Model model;
};

inline HeldBox held_box() {
  HeldBox held{structured_box(Eigen::Vector3d(0.1, 0.06, 0.04), 5, 3, 2, 0.1), Model{}};
  held.model = make_model(held.box.mesh, Material{3000.0, 0.45, 1000.0});
  Model& model = held.model;
  model.damping = Damping{0.01, 0.5};
  model.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
  model.dt = 0.01;
  SpringSet ligament{"x0_face", {}, 100.0, {}};
  SpringSet control{"control", {}, 50.0, {}};
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int n = 0; n < held.box.mesh.node_count(); ++n) {
    if (held.box.on_face(n, 0, 0)) ligament.nodes.push_back(n);
    if (held.box.on_face(n, 0, 1)) {
      control.nodes.push_back(n);
      centroid += held.box.mesh.nodes[n];
    }
  }
  model.ligaments.push_back(ligament);
  model.control = control;
  model.control_start = centroid / static_cast<double>(control.nodes.size());
  return held;
}

// Where the held box's SO is at time t: moving at 5 cm/s, mostly along z.
inline Eigen::Vector3d held_box_so(const Model& model, double t) {
  return model.control_start + t * Eigen::Vector3d(0.01, 0.02, 0.05);
}

}  // namespace sigmafem::test
