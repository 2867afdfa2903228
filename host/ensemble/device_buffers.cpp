#include "host/ensemble/device_buffers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "device_layout.h"

namespace sigmafem {
namespace {

// Offsets of a CSR list of `counts[n]` entries per node: offsets[n] .. offsets[n + 1].
std::vector<int> csr_offsets(std::vector<int> counts) {
  std::vector<int> offsets(counts.size() + 1, 0);
  for (std::size_t n = 0; n < counts.size(); ++n) offsets[n + 1] = offsets[n] + counts[n];
  return offsets;
}

// A kernel's buffers from (slot, buffer) pairs (device_layout.h); every slot given once.
std::vector<DeviceBuffer> by_slot(std::initializer_list<std::pair<int, DeviceBuffer>> slots) {
  std::vector<DeviceBuffer> buffers(slots.size(), DeviceBuffer::count);
  for (const auto& [slot, id] : slots) buffers.at(static_cast<std::size_t>(slot)) = id;
  if (std::count(buffers.begin(), buffers.end(), DeviceBuffer::count) > 0)
    throw std::logic_error("kernel_buffers: a slot given twice");
  return buffers;
}

}  // namespace

std::vector<DeviceBufferSpec> device_buffer_specs(const Model& model, const ObservedPoints& observed,
                                                  int S, std::size_t step_constant_count,
                                                  const DeviceBufferSizes& sizes,
                                                  const std::vector<int>& estimated_regions) {
  const int nodes = model.node_count(), elements = model.element_count();
  const int L = static_cast<int>(model.ligaments.size());
  const std::size_t dof = 3 * static_cast<std::size_t>(nodes) * S;
  const std::size_t per_element = static_cast<std::size_t>(elements) * S;

  std::vector<int> element_nodes(4 * static_cast<std::size_t>(elements));
  std::vector<double> element_rest(16 * static_cast<std::size_t>(elements), 0.0);
  std::vector<int> corners_per_node(nodes, 0), ligaments_per_node(nodes, 0);
  for (int e = 0; e < elements; ++e) {
    const ElementRest& element = model.elements[e];
    for (int c = 0; c < 4; ++c) {
      element_nodes[4 * e + c] = element.nodes[c];
      ++corners_per_node[element.nodes[c]];
    }
    std::copy(element.grad.begin(), element.grad.end(), element_rest.begin() + 16 * e);
    element_rest[16 * e + 12] = element.vlambda;
    element_rest[16 * e + 13] = element.vmu;
  }
  for (std::size_t k = 0; k < estimated_regions.size(); ++k)
    for (int e : model.regions.at(static_cast<std::size_t>(estimated_regions[k])).elements)
      element_rest[16 * static_cast<std::size_t>(e) + SF_REST_REGION_SLOT] = static_cast<double>(1 + k);
  const std::vector<int> incidence_offsets = csr_offsets(corners_per_node);
  std::vector<int> incidence(incidence_offsets[nodes]);
  std::vector<int> fill(incidence_offsets.begin(), incidence_offsets.end() - 1);
  for (int i = 0; i < 4 * elements; ++i) incidence[fill[element_nodes[i]]++] = i;

  for (const SpringSet& ligament : model.ligaments)
    for (int node : ligament.nodes) ++ligaments_per_node[node];
  const std::vector<int> ligament_offsets = csr_offsets(ligaments_per_node);
  std::vector<int> ligament_of_node(std::max(1, ligament_offsets[nodes]), 0);
  fill.assign(ligament_offsets.begin(), ligament_offsets.end() - 1);
  for (int l = 0; l < L; ++l)
    for (int node : model.ligaments[l].nodes) ligament_of_node[fill[node]++] = l;
  std::vector<double> ligament_k(static_cast<std::size_t>(std::max(1, L)) * S, 0.0);
  for (int l = 0; l < L; ++l) {
    const double per_node = model.ligaments[l].stiffness /
                            static_cast<double>(model.ligaments[l].nodes.size());
    std::fill_n(ligament_k.begin() + static_cast<std::ptrdiff_t>(l) * S, S, per_node);
  }
  std::vector<double> control_k(nodes, 0.0);
  for (std::size_t j = 0; j < model.control.nodes.size(); ++j)
    control_k[model.control.nodes[j]] += model.control.node_part(j, model.control.stiffness);
  std::vector<double> rest_positions(3 * static_cast<std::size_t>(nodes));
  for (int n = 0; n < nodes; ++n)
    for (int k = 0; k < 3; ++k) rest_positions[3 * n + k] = model.rest_positions[n][k];
  std::vector<double> initial_positions(dof);   // the rest shape for every sigma point
  for (std::size_t row = 0; row < 3 * static_cast<std::size_t>(nodes); ++row)
    std::fill_n(initial_positions.begin() + static_cast<std::ptrdiff_t>(row * S), S, rest_positions[row]);

  // The factor's arrays, written at its first refresh (one element each without a factor).
  const std::size_t rows = sizes.factor_nonzeros > 0 ? 3 * static_cast<std::size_t>(nodes) : 0;
  const std::size_t factor_nonzeros = std::max<std::size_t>(1, sizes.factor_nonzeros);
  const std::size_t spring_rows = static_cast<std::size_t>(sizes.spring_rows);

  const std::size_t groups = static_cast<std::size_t>(S) * sizes.cg_partitions;
  const std::size_t sigma = static_cast<std::size_t>(S);
  auto reals = [](DeviceBuffer id, const char* what, std::size_t count) {
    return DeviceBufferSpec{id, what, false, std::max<std::size_t>(1, count), {}, {}};
  };
  auto reals_of = [](DeviceBuffer id, const char* what, std::vector<double> values) {
    const std::size_t count = std::max<std::size_t>(1, values.size());
    return DeviceBufferSpec{id, what, false, count, std::move(values), {}};
  };
  auto integers = [](DeviceBuffer id, const char* what, std::vector<int> values) {
    const std::size_t count = values.size();
    return DeviceBufferSpec{id, what, true, count, {}, std::move(values)};
  };
  using B = DeviceBuffer;
  std::vector<DeviceBufferSpec> specs = {
      integers(B::element_nodes, "element nodes", element_nodes),
      reals_of(B::element_rest, "element rest state", element_rest),
      integers(B::incidence_offsets, "node incidence", incidence_offsets),
      integers(B::incidence, "node incidence", incidence),
      integers(B::ligament_offsets, "ligament nodes", ligament_offsets),
      integers(B::ligament_of_node, "ligament nodes", ligament_of_node),
      reals_of(B::control_k, "control springs", control_k),
      reals_of(B::mass, "mass", std::vector<double>(model.mass.data(), model.mass.data() + nodes)),
      reals_of(B::rest_positions, "rest positions", rest_positions),
      integers(B::observed_nodes, "observed points", corner_nodes(observed)),
      reals_of(B::observed_weights, "observed points", corner_weights(observed)),
      reals(B::constants, "step constants", step_constant_count),
      reals_of(B::ligament_k, "ligament stiffness", ligament_k),
      reals_of(B::x, "positions", initial_positions),
      reals_of(B::v, "velocities", std::vector<double>(dof, 0.0)),
      reals_of(B::dv, "velocity change", std::vector<double>(dof, 0.0)),
      reals(B::rhs, "CG vectors", dof),
      reals(B::inverse_diagonal, "CG vectors", sizes.jacobi_diagonals ? dof : 1),
      reals(B::r, "CG vectors", dof), reals(B::z, "CG vectors", sizes.cg_z ? dof : 1),
      reals(B::d, "CG vectors", dof), reals(B::q, "CG vectors", dof),
      reals(B::frames, "element frames", sizes.frame_numbers * per_element),
      reals(B::element_out, "element outputs", std::max(12 * per_element, sizes.element_out)),
      reals(B::element_diagonal, "element diagonals", sizes.jacobi_diagonals ? 12 * per_element : 1),
      reals(B::observations, "observations", std::max<std::size_t>(1, observed.size()) * 3 * sigma),
      reals(B::bb, "CG scalars", sigma), reals(B::rr, "CG scalars", sigma),
      reals(B::rz, "CG scalars", sigma),
      integers(B::active, "CG flags", std::vector<int>(sigma, 0)),
      integers(B::converged, "CG flags", std::vector<int>(sigma, 0)),
      integers(B::iterations, "CG flags", std::vector<int>(sigma, 0)),
      integers(B::all_active, "CG flags", std::vector<int>(sigma, 1)),
      reals(B::partial, "CG partial sums", 4 * groups),
      integers(B::own_active, "CG flags", std::vector<int>(groups, 0)),
      integers(B::own_iterations, "CG flags", std::vector<int>(groups, 0)),
      reals(B::own_rz, "CG scalars", groups),
      reals(B::recenter_scalars, "re-centring", 1 + kDeviceMaxParameters),
      reals(B::directions, "re-centring", static_cast<std::size_t>(kDeviceMaxParameters) * sigma),
      reals(B::weights, "re-centring", static_cast<std::size_t>(kDeviceMaxParameters) * sigma),
      integers(B::factor_columns, "the factor", std::vector<int>(rows + 1, 0)),
      integers(B::factor_rows, "the factor", std::vector<int>(factor_nonzeros, 0)),
      reals(B::factor_values, "the factor", factor_nonzeros * static_cast<std::size_t>(sizes.factor_copies)),
      integers(B::factor_order, "the factor", std::vector<int>(std::max<std::size_t>(1, rows), 0)),
      reals(B::factor_work, "the factor", rows * sigma),
      integers(B::spring_at, "the factor's spring correction",
               std::vector<int>(spring_rows > 0 ? rows + 1 : 1, 0)),
      reals_of(B::spring_solves, "the factor's spring correction",
               std::vector<double>(rows * spring_rows, 0.0)),
      reals_of(B::spring_coupling, "the factor's spring correction",
               std::vector<double>(spring_rows * spring_rows * sigma, 0.0)),
  };
  for (int i = 0; i < kDeviceBufferCount; ++i)   // the list above is in DeviceBuffer order
    if (specs[i].id != static_cast<DeviceBuffer>(i)) throw std::logic_error("device_buffer_specs: out of order");
  return specs;
}

const std::vector<DeviceBuffer>& kernel_buffers(DeviceKernel kernel) {
  using B = DeviceBuffer;
  // The buffers a node row reads (node_rows.h): the node kernels' first slots.
#define SF_NODE_ROW_SLOTS {SF_NODE_CONSTANTS, B::constants}, \
    {SF_NODE_INCIDENCE_OFFSETS, B::incidence_offsets}, {SF_NODE_INCIDENCE, B::incidence}, \
    {SF_NODE_LIGAMENT_OFFSETS, B::ligament_offsets}, \
    {SF_NODE_LIGAMENT_OF_NODE, B::ligament_of_node}, {SF_NODE_LIGAMENT_K, B::ligament_k}, \
    {SF_NODE_CONTROL_K, B::control_k}, {SF_NODE_MASS, B::mass}
  static const std::vector<std::vector<DeviceBuffer>> table = {
      // element_rhs
      by_slot({{SF_ELEMENT_RHS_ELEMENT_NODES, B::element_nodes},
               {SF_ELEMENT_RHS_ELEMENT_REST, B::element_rest}, {SF_ELEMENT_RHS_FRAMES, B::frames},
               {SF_ELEMENT_RHS_X, B::x}, {SF_ELEMENT_RHS_V, B::v},
               {SF_ELEMENT_RHS_CONSTANTS, B::constants},
               {SF_ELEMENT_RHS_ELEMENT_OUT, B::element_out},
               {SF_ELEMENT_RHS_ELEMENT_DIAGONAL, B::element_diagonal}}),
      // node_rhs
      by_slot({SF_NODE_ROW_SLOTS, {SF_NODE_RHS_REST_POSITIONS, B::rest_positions},
               {SF_NODE_RHS_X, B::x}, {SF_NODE_RHS_V, B::v},
               {SF_NODE_RHS_ELEMENT_OUT, B::element_out},
               {SF_NODE_RHS_ELEMENT_DIAGONAL, B::element_diagonal}, {SF_NODE_RHS_RHS, B::rhs},
               {SF_NODE_RHS_INVERSE_DIAGONAL, B::inverse_diagonal}}),
      // element_product
      by_slot({{SF_ELEMENT_PRODUCT_ELEMENT_NODES, B::element_nodes},
               {SF_ELEMENT_PRODUCT_ELEMENT_REST, B::element_rest},
               {SF_ELEMENT_PRODUCT_FRAMES, B::frames}, {SF_ELEMENT_PRODUCT_D, B::d},
               {SF_ELEMENT_PRODUCT_ACTIVE, B::active},
               {SF_ELEMENT_PRODUCT_ELEMENT_OUT, B::element_out},
               {SF_ELEMENT_PRODUCT_CONSTANTS, B::constants}}),
      // node_product
      by_slot({SF_NODE_ROW_SLOTS, {SF_NODE_PRODUCT_D, B::d},
               {SF_NODE_PRODUCT_ELEMENT_OUT, B::element_out}, {SF_NODE_PRODUCT_Q, B::q}}),
      // state_update
      by_slot({{SF_STATE_UPDATE_CONSTANTS, B::constants}, {SF_STATE_UPDATE_BB, B::bb},
               {SF_STATE_UPDATE_DV, B::dv}, {SF_STATE_UPDATE_X, B::x}, {SF_STATE_UPDATE_V, B::v}}),
      // observation_gather
      by_slot({{SF_OBSERVATION_GATHER_OBSERVED_NODES, B::observed_nodes},
               {SF_OBSERVATION_GATHER_OBSERVED_WEIGHTS, B::observed_weights},
               {SF_OBSERVATION_GATHER_X, B::x},
               {SF_OBSERVATION_GATHER_OBSERVATIONS, B::observations}}),
      // recenter
      by_slot({{SF_RECENTER_RECENTER_SCALARS, B::recenter_scalars},
               {SF_RECENTER_DIRECTIONS, B::directions}, {SF_RECENTER_WEIGHTS, B::weights},
               {SF_RECENTER_X, B::x}, {SF_RECENTER_V, B::v}}),
      // Vulkan's cg_start, cg_start_partials, cg_start_scalars
      by_slot({SF_NODE_ROW_SLOTS, {SF_CG_START_ELEMENT_OUT, B::element_out},
               {SF_CG_START_RHS, B::rhs}, {SF_CG_START_INVERSE_DIAGONAL, B::inverse_diagonal},
               {SF_CG_START_DV, B::dv}, {SF_CG_START_R, B::r}, {SF_CG_START_Z, B::z},
               {SF_CG_START_D, B::d}, {SF_CG_START_BB, B::bb}, {SF_CG_START_RR, B::rr},
               {SF_CG_START_RZ, B::rz}, {SF_CG_START_ACTIVE, B::active},
               {SF_CG_START_CONVERGED, B::converged}, {SF_CG_START_ITERATIONS, B::iterations},
               {SF_CG_START_PARTIAL, B::partial}, {SF_CG_START_OWN_ACTIVE, B::own_active},
               {SF_CG_START_OWN_ITERATIONS, B::own_iterations}, {SF_CG_START_OWN_RZ, B::own_rz}}),
      // Vulkan's cg_iteration, cg_node_iteration, cg_dot, cg_update, cg_direction
      by_slot({{SF_CG_ITERATION_CONSTANTS, B::constants},
               {SF_CG_ITERATION_INVERSE_DIAGONAL, B::inverse_diagonal},
               {SF_CG_ITERATION_DV, B::dv}, {SF_CG_ITERATION_R, B::r}, {SF_CG_ITERATION_Z, B::z},
               {SF_CG_ITERATION_D, B::d}, {SF_CG_ITERATION_Q, B::q}, {SF_CG_ITERATION_BB, B::bb},
               {SF_CG_ITERATION_RR, B::rr}, {SF_CG_ITERATION_RZ, B::rz},
               {SF_CG_ITERATION_ACTIVE, B::active}, {SF_CG_ITERATION_CONVERGED, B::converged},
               {SF_CG_ITERATION_ITERATIONS, B::iterations}, {SF_CG_ITERATION_PARTIAL, B::partial},
               {SF_CG_ITERATION_OWN_ACTIVE, B::own_active},
               {SF_CG_ITERATION_OWN_ITERATIONS, B::own_iterations},
               {SF_CG_ITERATION_OWN_RZ, B::own_rz},
               {SF_CG_ITERATION_INCIDENCE_OFFSETS, B::incidence_offsets},
               {SF_CG_ITERATION_INCIDENCE, B::incidence},
               {SF_CG_ITERATION_LIGAMENT_OFFSETS, B::ligament_offsets},
               {SF_CG_ITERATION_LIGAMENT_OF_NODE, B::ligament_of_node},
               {SF_CG_ITERATION_LIGAMENT_K, B::ligament_k}, {SF_CG_ITERATION_CONTROL_K, B::control_k},
               {SF_CG_ITERATION_MASS, B::mass}, {SF_CG_ITERATION_ELEMENT_OUT, B::element_out}}),
  };
#undef SF_NODE_ROW_SLOTS
  return table[static_cast<std::size_t>(kernel)];
}

std::vector<DeviceBuffer> with_buffer(std::vector<DeviceBuffer> buffers, DeviceBuffer from,
                                      DeviceBuffer to) {
  std::replace(buffers.begin(), buffers.end(), from, to);
  return buffers;
}

int buffer_slot(DeviceKernel kernel, DeviceBuffer buffer) {
  const std::vector<DeviceBuffer>& buffers = kernel_buffers(kernel);
  return static_cast<int>(std::find(buffers.begin(), buffers.end(), buffer) - buffers.begin());
}

Eigen::MatrixXd parameters_from_theta(const Model& model, const EstimatedParameters& estimated,
                                      const Eigen::MatrixXd& theta, int S, std::vector<double>& ligament_k) {
  for (std::size_t j = 0; j < estimated.ligaments.size(); ++j) {
    const int l = estimated.ligaments[j];
    const double nodes = static_cast<double>(model.ligaments[l].nodes.size());
    for (int s = 0; s < S; ++s)
      ligament_k[static_cast<std::size_t>(l) * S + s] =
          std::exp(theta(static_cast<Eigen::Index>(j), s)) / nodes;
  }
  Eigen::MatrixXd scales(static_cast<Eigen::Index>(estimated.regions.size()), S);
  for (std::size_t k = 0; k < estimated.regions.size(); ++k) {
    const double model_modulus = model.regions[static_cast<std::size_t>(estimated.regions[k])].young_modulus;
    for (int s = 0; s < S; ++s)
      scales(static_cast<Eigen::Index>(k), s) = std::exp(theta(estimated.region_row(k), s)) / model_modulus;
  }
  return scales;
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

}  // namespace sigmafem
