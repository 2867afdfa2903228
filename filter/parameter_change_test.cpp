#include "filter/parameter_change_test.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>

#include "filter/statistical_distributions.h"

namespace sigmafem {

ParameterChangeTest::ParameterChangeTest(const ParameterChangeTestOptions& options) : options_(options) {
  for (int w : options_.windows)
    if (w < 1) throw std::invalid_argument("ParameterChangeTest: every window needs at least one step");
}

ParameterChange ParameterChangeTest::update(const Eigen::VectorXd& score, const Eigen::MatrixXd& covariance,
                                            const std::vector<bool>& active,
                                            const std::vector<bool>& follow_up) {
  ParameterChange found;
  const Eigen::Index p = score.size();
  found.jump = Eigen::VectorXd::Zero(p);
  if (!options_.enabled || options_.windows.empty() || !score.allFinite() || !covariance.allFinite())
    return found;
  const int longest = *std::max_element(options_.windows.begin(), options_.windows.end());
  steps_.push_back({score, covariance});
  while (static_cast<int>(steps_.size()) > longest) steps_.pop_front();
  std::vector<Eigen::Index> tested;
  for (Eigen::Index j = 0; j < p; ++j)
    if (active[static_cast<std::size_t>(j)]) tested.push_back(j);
  if (tested.empty()) return found;

  double best_significance = 0.0;   // T / threshold of the most significant window that fired
  for (int w : options_.windows) {
    if (static_cast<int>(steps_.size()) < w) continue;
    Eigen::VectorXd G = Eigen::VectorXd::Zero(p);
    Eigen::MatrixXd V = Eigen::MatrixXd::Zero(p, p);
    for (auto it = steps_.end() - w; it != steps_.end(); ++it) {
      G += it->score;
      V += it->covariance;
    }
    const Eigen::VectorXd G_a = G(tested);
    const Eigen::MatrixXd V_a = V(tested, tested);
    // V^+ on its numerical range: a parameter the data no longer see (a spring near zero) adds
    // no degree of freedom.
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (V_a + V_a.transpose()));
    const Eigen::VectorXd lambda = eigen.eigenvalues();
    const double floor = 1e-12 * std::max(lambda.maxCoeff(), 0.0);
    const Eigen::VectorXd projected = eigen.eigenvectors().transpose() * G_a;
    double T = 0.0;
    int rank = 0;
    for (Eigen::Index i = 0; i < lambda.size(); ++i)
      if (lambda[i] > floor && lambda[i] > 0.0) {
        T += projected[i] * projected[i] / lambda[i];
        ++rank;
      }
    if (rank == 0) continue;
    const double threshold = chi_square_tail_quantile(options_.false_alarm, rank);
    if (T <= threshold || T / threshold <= best_significance) continue;
    best_significance = T / threshold;
    found.fired = true;
    found.window = w;
    found.statistic = T;
    found.threshold = threshold;
    // Which parameter jumped: the single-parameter hypotheses' statistics G_j^2 / V_jj (the
    // failure isolation of Willsky and Jones), the largest taken; its jump G_j / V_jj.
    Eigen::Index culprit = 0;
    for (Eigen::Index i = 1; i < G_a.size(); ++i)
      if (G_a[i] * G_a[i] / V_a(i, i) > G_a[culprit] * G_a[culprit] / V_a(culprit, culprit)) culprit = i;
    Eigen::VectorXd nu_a = Eigen::VectorXd::Zero(G_a.size());
    if (V_a(culprit, culprit) > 0.0) nu_a[culprit] = G_a[culprit] / V_a(culprit, culprit);
    found.jump(tested) = nu_a;
  }
  // The follow-up: each recently changed parameter alone, if no joint window fired.
  const bool joint = found.fired;
  const double follow_up_threshold = chi_square_tail_quantile(options_.follow_up_false_alarm, 1);
  for (std::size_t i = 0; i < follow_up.size() && !joint; ++i) {
    const auto j = static_cast<Eigen::Index>(i);
    if (!follow_up[i] || !active[i]) continue;
    for (int w : options_.windows) {
      if (static_cast<int>(steps_.size()) < w) continue;
      double G = 0.0, V = 0.0;
      for (auto it = steps_.end() - w; it != steps_.end(); ++it) {
        G += it->score[j];
        V += it->covariance(j, j);
      }
      if (!(V > 0.0) || G * G / V <= follow_up_threshold || G * G / V / follow_up_threshold <= best_significance) continue;
      best_significance = G * G / V / follow_up_threshold;
      found.fired = true;
      found.window = w;
      found.statistic = G * G / V;
      found.threshold = follow_up_threshold;
      found.follow_up = true;
      found.jump.setZero();
      found.jump[j] = G / V;
    }
  }
  if (found.fired) steps_.clear();
  return found;
}

}  // namespace sigmafem
