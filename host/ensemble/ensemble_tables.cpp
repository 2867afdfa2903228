#include "host/ensemble/ensemble_tables.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "host/common/input_error.h"
#include "step_constants.h"

namespace sigmafem {

double device_cg_tolerance(const Model& model, Precision precision) {
  return precision == Precision::single ? std::max(model.solver.cg_tolerance, kSingleCgTolerance)
                                        : model.solver.cg_tolerance;
}

void check_ensemble_arguments(const Model& model, const std::vector<int>& estimated,
                              const ObservedPoints& observed, int S, const char* who) {
  const std::string name(who);
  if (S < 1) throw std::invalid_argument(name + ": need at least one sigma point");
  if (static_cast<int>(estimated.size()) > kDeviceMaxParameters)
    throw std::invalid_argument(name + ": at most " + std::to_string(kDeviceMaxParameters) +
                                " estimated parameters");
  for (int l : estimated)
    if (l < 0 || l >= static_cast<int>(model.ligaments.size()))
      throw std::invalid_argument(name + ": no ligament " + std::to_string(l));
  check_observed_points(observed, model.node_count(), who);
  // The kernels give every node of a ligament the same part of its stiffness (one number per
  // ligament and sigma point); the control's parts are per node and need no check.
  for (const SpringSet& ligament : model.ligaments)
    if (!ligament.shares.empty())
      throw InputError(name + ": ligament " + ligament.name +
                       " gives its nodes unequal parts of its stiffness (generate --truth-refine spreads each "
                       "spring over the refined mesh), which the device back ends do not hold: use --backend cpu");
}

int cg_partitions(int nodes, int forced) {
  if (forced > 0) return forced;
  return std::clamp(3 * nodes / kPartitionRows, 1, kMostPartitions);
}

EnsembleTables make_ensemble_tables(const Model& model, int S) {
  const int nodes = model.node_count(), elements = model.element_count();
  EnsembleTables t;
  t.element_nodes.assign(4 * static_cast<std::size_t>(elements), 0);
  t.element_rest.assign(16 * static_cast<std::size_t>(elements), 0.0);
  t.incidence_offsets.assign(nodes + 1, 0);
  for (int e = 0; e < elements; ++e) {
    const ElementRest& element = model.elements[e];
    for (int c = 0; c < 4; ++c) {
      t.element_nodes[4 * e + c] = element.nodes[c];
      ++t.incidence_offsets[element.nodes[c] + 1];
    }
    std::copy(element.grad.begin(), element.grad.end(), t.element_rest.begin() + 16 * e);
    t.element_rest[16 * e + 12] = element.vlambda;
    t.element_rest[16 * e + 13] = element.vmu;
  }
  for (int n = 0; n < nodes; ++n) t.incidence_offsets[n + 1] += t.incidence_offsets[n];
  t.incidence.assign(t.incidence_offsets[nodes], 0);
  std::vector<int> fill(t.incidence_offsets.begin(), t.incidence_offsets.end() - 1);
  for (int e = 0; e < elements; ++e)
    for (int c = 0; c < 4; ++c) t.incidence[fill[t.element_nodes[4 * e + c]]++] = 4 * e + c;

  const int L = static_cast<int>(model.ligaments.size());
  t.ligament_offsets.assign(nodes + 1, 0);
  for (const SpringSet& ligament : model.ligaments)
    for (int node : ligament.nodes) ++t.ligament_offsets[node + 1];
  for (int n = 0; n < nodes; ++n) t.ligament_offsets[n + 1] += t.ligament_offsets[n];
  t.ligament_of_node.assign(std::max(1, t.ligament_offsets[nodes]), 0);
  fill.assign(t.ligament_offsets.begin(), t.ligament_offsets.end() - 1);
  for (int l = 0; l < L; ++l)
    for (int node : model.ligaments[l].nodes) t.ligament_of_node[fill[node]++] = l;
  t.ligament_k.assign(static_cast<std::size_t>(std::max(1, L)) * S, 0.0);
  for (int l = 0; l < L; ++l) {
    const double per_node = model.ligaments[l].stiffness /
                            static_cast<double>(model.ligaments[l].nodes.size());
    for (int s = 0; s < S; ++s) t.ligament_k[static_cast<std::size_t>(l) * S + s] = per_node;
  }
  t.control_k.assign(nodes, 0.0);
  for (std::size_t j = 0; j < model.control.nodes.size(); ++j)
    t.control_k[model.control.nodes[j]] += model.control.node_part(j, model.control.stiffness);
  t.mass.assign(model.mass.data(), model.mass.data() + nodes);
  t.rest_positions.resize(3 * static_cast<std::size_t>(nodes));
  for (int n = 0; n < nodes; ++n)
    for (int k = 0; k < 3; ++k) t.rest_positions[3 * n + k] = model.rest_positions[n][k];
  t.initial_positions.resize(3 * static_cast<std::size_t>(nodes) * S);
  for (std::size_t row = 0; row < 3 * static_cast<std::size_t>(nodes); ++row)
    for (int s = 0; s < S; ++s) t.initial_positions[row * S + s] = t.rest_positions[row];
  return t;
}

void set_ligament_stiffness(const Model& model, const std::vector<int>& estimated,
                            const Eigen::MatrixXd& theta, int S, std::vector<double>& ligament_k) {
  for (std::size_t j = 0; j < estimated.size(); ++j) {
    const int l = estimated[j];
    const double nodes = static_cast<double>(model.ligaments[l].nodes.size());
    for (int s = 0; s < S; ++s)
      ligament_k[static_cast<std::size_t>(l) * S + s] =
          std::exp(theta(static_cast<Eigen::Index>(j), s)) / nodes;
  }
}

StepConstants::StepConstants(const Model& model, int sigma_count, double cg_tolerance)
    : physics_(static_cast<std::size_t>(std::max(sigma_count, 0))),
      so_history_(model.control_start, model.dt),
      cg_tolerance_(cg_tolerance) {}

void StepConstants::set_physics_effects(const std::vector<PhysicsEffects>& effects, const std::string& who) {
  if (effects.size() != physics_.size())
    throw std::invalid_argument(who + "::set_physics_effects: expected one entry per sigma point");
  physics_ = effects;
}

std::size_t StepConstants::size() const { return SF_STEP_CONSTANTS + SF_SIGMA_CONSTANT_COUNT * physics_.size(); }

std::vector<double> StepConstants::next_step(const Model& m, const Eigen::Vector3d& so_position) {
  so_history_.push(so_position);
  const double h = m.dt;
  const std::size_t S = physics_.size();
  std::vector<double> c(size());
  c[SF_H] = h;
  c[SF_CG_TOLERANCE2] = cg_tolerance_ * cg_tolerance_;
  c[SF_POLAR_ROTATION] = m.material.rotation == ElementRotation::polar ? 1.0 : 0.0;
  for (std::size_t s = 0; s < S; ++s) {
    const PhysicsEffects& e = physics_[s];
    auto at = [&](int k) -> double& { return c[SF_STEP_CONSTANTS + k * S + s]; };
    const Eigen::Vector3d gravity = m.gravity + e.gravity;
    const Eigen::Vector3d shift =
        m.control_scale * e.control_scale * (so_history_.lagged(m.so_lag + e.time_lag) - m.control_start);
    const double d0 = std::isfinite(e.ligament_d0) ? e.ligament_d0 : m.ligament_d0;
    const double a = e.damping_stiffness_scale * m.damping.rayleigh_stiffness;
    const double b = e.damping_mass_scale * m.damping.rayleigh_mass;
    for (int k = 0; k < 3; ++k) {
      at(SF_GRAVITY + k) = gravity[k];
      at(SF_SO_SHIFT + k) = shift[k];
    }
    at(SF_INVERSE_D0_SQUARED) = 1.0 / (d0 * d0);   // 0 for the linear law (infinite d0)
    at(SF_YOUNG_SCALE) = e.young_scale;
    at(SF_LAMBDA_SCALE) = e.lambda_scale;
    at(SF_MASS_FACTOR) = 1.0 + h * b;
    at(SF_STIFFNESS_FACTOR) = h * (h + a);
    at(SF_RAYLEIGH_MASS) = b;
    at(SF_VELOCITY_FACTOR) = h + a;
  }
  return c;
}

RecenteringInputs pack_recentering(const Recentering& r, int S, const char* who) {
  const int p = static_cast<int>(r.directions.rows());
  if (r.directions.cols() != S || r.correction.size() != p || r.factor.rows() != p || r.factor.cols() != p)
    throw std::invalid_argument(std::string(who) + "::recenter: sizes do not match the ensemble");
  if (p > kDeviceMaxParameters)
    throw std::invalid_argument(std::string(who) + "::recenter: at most " + std::to_string(kDeviceMaxParameters) +
                                " filter parameters on a device, got " + std::to_string(p));
  const Eigen::MatrixXd weights = r.factor * r.directions;   // W = C I
  RecenteringInputs in;
  in.p = static_cast<std::uint32_t>(p);
  in.scalars.assign(1 + kDeviceMaxParameters, 0.0);
  in.directions.resize(static_cast<std::size_t>(p) * S);
  in.weights.resize(static_cast<std::size_t>(p) * S);
  in.scalars[0] = r.alpha;
  for (int j = 0; j < p; ++j) {
    in.scalars[1 + j] = r.correction[j];
    for (int s = 0; s < S; ++s) {
      in.directions[static_cast<std::size_t>(j) * S + s] = r.directions(j, s);
      in.weights[static_cast<std::size_t>(j) * S + s] = weights(j, s);
    }
  }
  return in;
}

EnsembleMemory ensemble_memory(int nodes, int elements, int S, std::size_t real_size) {
  // Per dof and sigma: x, v, dv, rhs, the Jacobi diagonal, r, z, d, q; per element and sigma:
  // the frame (9), the element outputs (12) and diagonals (12).
  const std::size_t dof = 3 * static_cast<std::size_t>(nodes) * S;
  const std::size_t per_element = static_cast<std::size_t>(elements) * S;
  EnsembleMemory need;
  need.largest = 12 * per_element * real_size;
  need.total = (9 * dof + 33 * per_element) * real_size;
  return need;
}

std::string out_of_device_memory_message(const EnsembleMemory& need, int elements, int S,
                                         const std::string& device,
                                         std::size_t device_memory, std::size_t largest_buffer) {
  return "out of device memory: " + std::to_string(S) + " sigma points on " +
         std::to_string(elements) + " tetrahedra need about " + std::to_string(need.total >> 20) +
         " MiB (largest buffer " + std::to_string(need.largest >> 20) + " MiB); " + device +
         " has " + std::to_string(device_memory >> 20) + " MiB (largest buffer " +
         std::to_string(largest_buffer >> 20) +
         " MiB). Use fewer sigma points, a coarser mesh or another device";
}

}  // namespace sigmafem
