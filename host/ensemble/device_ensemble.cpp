#include "host/ensemble/device_ensemble.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "device_layout.h"
#include "host/common/device_error.h"
#include "host/ensemble/device_limits.h"
#include "host/ensemble/device_readout.h"
#include "host/model/shared_element.h"

namespace sigmafem {

DeviceEnsemble::DeviceEnsemble(const Model& model, EstimatedParameters estimated,
                               ObservedPoints observed, int sigma_count, Precision precision,
                               const char* backend, const char* who)
    : model_(model),
      estimated_(std::move(estimated)),
      observed_(std::move(observed)),
      S_(sigma_count),
      nodes_(model.node_count()),
      elements_(model.element_count()),
      precision_(precision),
      tolerance_(device_cg_tolerance(model, precision)),
      step_constants_(model, sigma_count, tolerance_, static_cast<int>(estimated_.regions.size())),
      backend_(backend),
      who_(who) {
  check_ensemble_arguments(model, estimated_, observed_, S_, who);
}

void DeviceEnsemble::check_device_memory(const std::string& name, std::size_t memory,
                                         std::size_t largest_buffer, const DeviceOptions& options) {
  device_memory_ = usable_device_memory(memory, options);
  largest_buffer_ = largest_buffer;
  device_name_ = memory_holder(name, memory, options);
  check_device_memory_with_factor(0, FactorStorage::columns);
}

void DeviceEnsemble::check_device_memory_with_factor(std::size_t factor_nonzeros, FactorStorage storage,
                                                     int factor_copies) const {
  const EnsembleMemory need = ensemble_memory(nodes_, elements_, S_, real_size(precision_), factor_nonzeros, storage,
                                             factor_copies, frame_numbers());
  if (need.largest > largest_buffer_ || need.total > device_memory_)
    throw DeviceError(
        out_of_device_memory_message(need, elements_, S_, device_name_, device_memory_, largest_buffer_));
}

void DeviceEnsemble::check_more_device_memory(std::size_t more, const std::string& what) const {
  if (device_bytes_ + more > device_memory_)
    throw DeviceError(out_of_device_memory_message(what, more, device_bytes_, device_name_, device_memory_));
}

std::vector<DeviceBufferSpec> DeviceEnsemble::buffer_specs(const DeviceBufferSizes& sizes) {
  std::vector<DeviceBufferSpec> specs =
      device_buffer_specs(model_, observed_, S_, step_constants_.size(), sizes, estimated_.regions);
  ligament_k_ = specs[static_cast<int>(DeviceBuffer::ligament_k)].reals;
  return specs;
}

std::size_t DeviceEnsemble::take_device_bytes(const DeviceBufferSpec& spec, std::size_t real_size) {
  const std::size_t bytes = spec.count * (spec.integer ? sizeof(std::int32_t) : real_size);
  device_bytes_ += bytes;
  return bytes;
}

StepReport DeviceEnsemble::step_report(const std::vector<std::int32_t>& iterations,
                                       const std::vector<std::uint32_t>& converged,
                                       const std::vector<double>& rr, const std::vector<double>& bb) {
  expected_iterations_ = *std::max_element(iterations.begin(), iterations.end());
  return solver_report(iterations, converged, rr, bb);
}

void DeviceEnsemble::set_parameters(const Eigen::MatrixXd& theta) {
  check_parameter_matrix(theta, parameter_count(), sigma_count(), who_);
  step_constants_.set_region_scales(parameters_from_theta(model_, estimated_, theta, S_, ligament_k_));
  upload_ligament_k();
  theta_ = theta;
}

void DeviceEnsemble::set_physics_effects(const std::vector<PhysicsEffects>& effects) {
  step_constants_.set_physics_effects(effects, who_);
  effects_ = effects;
}

Eigen::SparseMatrix<double> DeviceEnsemble::system_at(const Eigen::VectorXd& theta, const PhysicsEffects& effects,
                                                      const Eigen::VectorXd& x, const Eigen::VectorXd& v) const {
  if (!representative_) representative_ = std::make_unique<ReferenceSimulation>(model_);
  // Before set_parameters the model's values (theta still empty).
  std::vector<double> stiffness = representative_->ligament_stiffness(), moduli;
  for (const ElasticRegion& region : model_.regions) moduli.push_back(region.young_modulus);
  if (theta.size() == estimated_.count()) apply_parameters(model_, estimated_, theta, stiffness, moduli);
  representative_->set_ligament_stiffness(stiffness);
  representative_->set_region_young_modulus(moduli);
  representative_->set_physics_effects(effects);
  representative_->set_state(x, v);
  return representative_->system_matrix();
}

Eigen::SparseMatrix<double> DeviceEnsemble::representative_system(const Eigen::VectorXd& x,
                                                                  const Eigen::VectorXd& v) const {
  // The sigma points' mean parameters and sigma point 0's effects (none set yet: the model's).
  const Eigen::VectorXd theta = theta_.size() > 0 ? Eigen::VectorXd(theta_.rowwise().mean()) : Eigen::VectorXd();
  return system_at(theta, effects_.empty() ? PhysicsEffects{} : effects_.front(), x, v);
}

Eigen::SparseMatrix<double> DeviceEnsemble::sigma_system(int s, const Eigen::VectorXd& x, const Eigen::VectorXd& v) const {
  const Eigen::VectorXd theta = theta_.size() > 0 ? Eigen::VectorXd(theta_.col(s)) : Eigen::VectorXd();
  return system_at(theta, effects_.empty() ? PhysicsEffects{} : effects_.at(static_cast<std::size_t>(s)), x, v);
}

std::unique_ptr<FactorisedPreconditioner> DeviceEnsemble::analysed_factor(const SpringCorrection& springs) const {
  auto factor = std::make_unique<FactorisedPreconditioner>(springs.rows());
  const ReferenceSimulation rest(model_);
  factor->analyse(representative_system(rest.positions(), rest.velocities()));
  return factor;
}

SpringCorrection DeviceEnsemble::spring_correction(bool asked) const {
  std::vector<int> rows = estimated_spring_rows(model_, estimated_);
  if (!asked || !spring_correction_fits(rows.size(), S_)) return SpringCorrection();
  return SpringCorrection(std::move(rows));
}

std::vector<double> DeviceEnsemble::factorised_springs(const SpringCorrection& springs,
                                                       const std::vector<double>& constants) const {
  return spring_diagonal(springs, constants, 0, representative_ligament_k());
}

std::vector<double> DeviceEnsemble::spring_diagonal(const SpringCorrection& springs,
                                                    const std::vector<double>& constants, int s,
                                                    const std::vector<double>& ligament_k) const {
  // The other springs are the same for all sigma points, and cancel.
  const double factor = constants[SF_STEP_CONSTANTS + SF_STIFFNESS_FACTOR * S_ + s];
  std::vector<double> node_k(static_cast<std::size_t>(nodes_), 0.0);
  for (int l : estimated_.ligaments)
    for (int node : model_.ligaments[static_cast<std::size_t>(l)].nodes)
      node_k[static_cast<std::size_t>(node)] += ligament_k[static_cast<std::size_t>(l) * S_ + s];
  const std::vector<int>& rows = springs.rows();
  std::vector<double> diagonal(rows.size());
  for (std::size_t j = 0; j < rows.size(); ++j) diagonal[j] = factor * node_k[static_cast<std::size_t>(rows[j] / 3)];
  return diagonal;
}

std::vector<double> DeviceEnsemble::spring_couplings(const SpringCorrection& springs,
                                                     const std::vector<double>& constants,
                                                     const std::vector<double>& factorised) const {
  const std::size_t m = static_cast<std::size_t>(springs.size());
  const std::vector<double> shifts = spring_shifts(springs, constants, factorised);
  std::vector<double> couplings(m * m * static_cast<std::size_t>(S_));
  for (int s = 0; s < S_; ++s) {
    Eigen::VectorXd delta(static_cast<Eigen::Index>(m));
    for (std::size_t j = 0; j < m; ++j) delta[static_cast<Eigen::Index>(j)] = shifts[j * static_cast<std::size_t>(S_) + static_cast<std::size_t>(s)];
    const Eigen::MatrixXd H = springs.coupling(delta);
    for (std::size_t j = 0; j < m; ++j)
      for (std::size_t k = 0; k < m; ++k)
        couplings[(static_cast<std::size_t>(s) * m + j) * m + k] =
            H(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(k));
  }
  return couplings;
}

std::vector<double> DeviceEnsemble::spring_shifts(const SpringCorrection& springs, const std::vector<double>& constants,
                                                  const std::vector<double>& factorised) const {
  const std::size_t m = static_cast<std::size_t>(springs.size());
  std::vector<double> shifts(m * static_cast<std::size_t>(S_));
  for (int s = 0; s < S_; ++s) {
    const std::vector<double> own = spring_diagonal(springs, constants, s, ligament_k_);
    for (std::size_t j = 0; j < m; ++j) shifts[j * static_cast<std::size_t>(S_) + static_cast<std::size_t>(s)] = own[j] - factorised[j];
  }
  return shifts;
}

std::vector<double> DeviceEnsemble::spring_shift_rows(const SpringCorrection& springs,
                                                      const std::vector<double>& constants,
                                                      const std::vector<double>& factorised) const {
  const std::size_t S = static_cast<std::size_t>(S_);
  std::vector<double> shift(3 * static_cast<std::size_t>(nodes_) * S, 0.0);
  const std::vector<double> own = spring_shifts(springs, constants, factorised);
  const std::vector<int>& rows = springs.rows();
  for (std::size_t j = 0; j < rows.size(); ++j)
    for (std::size_t s = 0; s < S; ++s) shift[static_cast<std::size_t>(rows[j]) * S + s] = own[j * S + s];
  return shift;
}

std::vector<double> DeviceEnsemble::representative_ligament_k() const {
  std::vector<double> k = ligament_k_;
  if (theta_.size() > 0)
    parameters_from_theta(model_, estimated_, Eigen::MatrixXd(theta_.rowwise().mean().replicate(1, S_)), S_, k);
  return k;
}

Eigen::SparseMatrix<double> DeviceEnsemble::representative_system() const {
  return representative_system_later()();
}

std::function<Eigen::SparseMatrix<double>()> DeviceEnsemble::representative_system_later() const {
  const std::size_t rows = 3 * static_cast<std::size_t>(nodes_);
  const auto mean = [&](DeviceBuffer buffer) -> Eigen::VectorXd {
    return from_sigma_rows(read_reals(buffer, rows * S_), rows, S_).rowwise().mean();
  };
  // As representative_system(x, v), with copies of what the next steps change.
  const Eigen::VectorXd theta = theta_.size() > 0 ? Eigen::VectorXd(theta_.rowwise().mean()) : Eigen::VectorXd();
  return [this, theta, effects = effects_.empty() ? PhysicsEffects{} : effects_.front(), x = mean(DeviceBuffer::x),
          v = mean(DeviceBuffer::v)] { return system_at(theta, effects, x, v); };
}

std::vector<double> DeviceEnsemble::column_of(DeviceBuffer buffer, std::size_t rows, int s) const {
  return sigma_column(read_reals(buffer, rows * S_), rows, S_, s, who_);
}

void DeviceEnsemble::read_states(Eigen::MatrixXd& positions, Eigen::MatrixXd& velocities) const {
  const std::size_t rows = 3 * static_cast<std::size_t>(nodes_);
  positions = from_sigma_rows(read_reals(DeviceBuffer::x, rows * S_), rows, S_);
  velocities = from_sigma_rows(read_reals(DeviceBuffer::v, rows * S_), rows, S_);
}

void DeviceEnsemble::write_states(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& velocities) {
  check_state_matrices(positions, velocities, 3 * static_cast<Eigen::Index>(nodes_), S_, who_);
  write_reals(DeviceBuffer::x, to_sigma_rows(positions));
  write_reals(DeviceBuffer::v, to_sigma_rows(velocities));
}

Eigen::VectorXd DeviceEnsemble::positions(int s) const {
  const std::vector<double> column = column_of(DeviceBuffer::x, 3 * static_cast<std::size_t>(nodes_), s);
  return Eigen::Map<const Eigen::VectorXd>(column.data(), static_cast<Eigen::Index>(column.size()));
}

Eigen::VectorXd DeviceEnsemble::velocities(int s) const {
  const std::vector<double> column = column_of(DeviceBuffer::v, 3 * static_cast<std::size_t>(nodes_), s);
  return Eigen::Map<const Eigen::VectorXd>(column.data(), static_cast<Eigen::Index>(column.size()));
}

std::size_t DeviceEnsemble::frame_numbers() const { return frames_keep_two_rows_ ? SF_FRAME_TWO_ROWS : 9; }

std::vector<double> DeviceEnsemble::frames(int s) const {
  const std::vector<double> kept = column_of(DeviceBuffer::frames, frame_numbers() * elements_, s);
  if (!frames_keep_two_rows_) return kept;
  std::vector<double> frames(9 * static_cast<std::size_t>(elements_));
  for (std::size_t e = 0; e < static_cast<std::size_t>(elements_); ++e) {
    std::copy_n(&kept[SF_FRAME_TWO_ROWS * e], SF_FRAME_TWO_ROWS, &frames[9 * e]);
    shared::sf_frame_third_row(&frames[9 * e]);
  }
  return frames;
}

Eigen::MatrixXd DeviceEnsemble::system_product(const Eigen::MatrixXd& d) {
  const std::size_t rows = 3 * static_cast<std::size_t>(nodes_);
  if (static_cast<std::size_t>(d.rows()) != rows || d.cols() != S_)
    throw std::invalid_argument(std::string(who_) + "::system_product: expected 3N x S");
  write_reals(DeviceBuffer::d, to_sigma_rows(d));
  run_system_product();
  return from_sigma_rows(read_reals(DeviceBuffer::q, rows * S_), rows, S_);
}

std::string DeviceEnsemble::description() const {
  return device_ensemble_description(backend_, precision_, device_name());
}

}  // namespace sigmafem
