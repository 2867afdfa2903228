// EffectEnsemble: an Ensemble whose parameters are the inner ensemble's log-stiffnesses
// followed by the parameters of candidate effects (host/scenario/effect_catalogue.h), so that
// the ROUKF estimates the effects as extra sigma-point dimensions with no change to the filter.
//
// Rows of theta: [the declared estimated ligaments' log-stiffnesses (p0); effect
// coordinates], the coordinate of an effect parameter being (u - prior_mean) / prior_std with
// u = log(value) or value (its transform): prior N(0, 1) for every effect coordinate.
//   physics effects (gravity, young_scale, ligament_law, time_lag, damping_scale): per sigma
//     point through the inner SimulationEnsemble's set_physics_effects, on any back end;
//   ligament effects (extra_ligament:REGION): one more estimated ligament of the inner
//     ensemble (make() appends it to the model), its log-stiffness mapped from the
//     coordinate: any back end;
//   observation effects (camera_offset): added to the inner ensemble's predicted
//     observations, per sigma point, on any back end.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "host/ensemble/simulation_ensemble.h"
#include "host/scenario/effect_catalogue.h"

namespace sigmafem {

class EffectEnsemble : public Ensemble {
 public:
  // `effects`: names of candidate effects, each at most once. `inner` estimates the declared
  // ligaments, then one ligament per ligament effect, in the order of `effects`
  // (make_effect_ensemble, host/engine/make_ensemble.h, builds such an inner). Throws
  // InputError for an unknown name or one that is not a candidate.
  EffectEnsemble(std::unique_ptr<SimulationEnsemble> inner, const std::vector<std::string>& effects);

  int sigma_count() const override { return inner_->sigma_count(); }
  int parameter_count() const override { return declared_count_ + effect_parameter_count_; }
  int observation_count() const override { return inner_->observation_count(); }
  void set_parameters(const Eigen::MatrixXd& theta) override;
  StepReport advance(const Eigen::Vector3d& so_position) override;
  void predicted_observations(Eigen::MatrixXd& y) const override;
  void recenter(const Recentering& recentering) override;
  int rows_per_point() const override { return inner_->rows_per_point(); }
  bool predicts_row(Eigen::Index row) const override { return inner_->predicts_row(row); }
  std::vector<int> rejected_points() const override { return inner_->rejected_points(); }

  const std::vector<const EffectDefinition*>& effects() const { return effects_; }

  // The value of `definition` (natural units) at its coordinates `coordinates`.
  static std::vector<double> effect_value(const EffectDefinition& definition,
                                          const Eigen::VectorXd& coordinates);
  // The value and its first-order standard deviation from the coordinates' mean and std.
  static void effect_estimate(const EffectDefinition& definition, const Eigen::VectorXd& coordinates,
                              const Eigen::VectorXd& coordinate_std, std::vector<double>& value,
                              std::vector<double>& value_std);

 private:
  std::unique_ptr<SimulationEnsemble> inner_;
  std::vector<const EffectDefinition*> effects_;
  int declared_count_ = 0;                         // p0: the declared estimated ligaments
  int effect_parameter_count_ = 0;
  Eigen::MatrixXd inner_theta_;                    // the inner ensemble's parameters
  Eigen::MatrixXd camera_offsets_;                 // 3 x S
};

}  // namespace sigmafem
