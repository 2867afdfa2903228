#include "host/diagnosis/diagnosis_conclusion.h"

#include <cmath>
#include <sstream>

namespace sigmafem {
namespace {

// A share as a percentage: one decimal from 1% up (99.9%, not 1e+02%), two digits below.
std::string percent(double share) {
  const double p = 100.0 * share;
  std::ostringstream out;
  if (std::abs(p) >= 1.0) {
    out.setf(std::ios::fixed);
    out.precision(1);
  } else {
    out.precision(2);
  }
  out << p << '%';
  return out.str();
}

std::string describe_estimate(const EffectEstimate& e) {
  std::ostringstream out;
  out << e.name << " = ";
  for (std::size_t j = 0; j < e.value.size(); ++j)
    out << (j ? ", " : "") << significant_digits(e.value[j]) << " +- " << significant_digits(e.std[j], 2);
  if (!e.units.empty() && !e.units[0].empty()) out << ' ' << e.units[0];
  return out.str();
}

}  // namespace

std::string significant_digits(double x, int digits) {
  std::ostringstream out;
  out.precision(digits);
  out << x;
  return out.str();
}

std::string diagnosis_conclusion(const Diagnosis& d, const std::vector<std::string>& library) {
  const ModelFit& after = d.after();
  std::ostringstream text;
  if (d.outcome == DiagnosisOutcome::consistent) {
    text << "The declared model explains the data: the residual is consistent, nothing was added.";
    return text.str();
  }
  if (d.outcome == DiagnosisOutcome::explained) {
    text << "The declared model left an inconsistent residual; adding ";
    for (std::size_t j = 0; j < after.estimates.size(); ++j)
      text << (j ? ", then " : "") << describe_estimate(after.estimates[j]);
    text << " makes it consistent.";
    // Another candidate that also made the residual consistent is an alternative the data
    // cannot rule out (e.g. a scale of Young's modulus and a gravity along the known one,
    // when that gravity is the only known force): say so rather than hide it.
    for (const DiagnosisRound& r : d.rounds)
      for (const CandidateScore& c : r.candidates)
        if (!r.chosen.empty() && c.effect != r.chosen && c.complete && c.verdict == Consistency::consistent)
          text << " Also consistent instead of " << r.chosen << ": " << describe_estimate(c.estimate)
               << " (score " << significant_digits(c.score, 6) << "): the data may not tell the two apart.";
    return text.str();
  }
  if (after.residual.verdict.consistency == Consistency::too_few_steps) {
    text << "Too few filter steps to judge the residual: nothing was tested or added.";
    return text.str();
  }
  if (d.outcome == DiagnosisOutcome::partly_explained) {
    const int claimed = d.after_position;
    text << "The residual stays inconsistent, but ";
    for (int j = 0; j < claimed; ++j) {
      const EffectEstimate& e = after.estimates[static_cast<std::size_t>(j)];
      text << (j ? ", then " : "") << describe_estimate(e) << " ("
           << percent(d.misfit.removed[static_cast<std::size_t>(j)]) << " of the declared model's misfit)";
    }
    const double left = after.residual.nis.mean - after.residual.nis.mean_dof;
    text << " account" << (claimed == 1 ? "s" : "") << " for most of it; "
         << percent(left / d.misfit.declared_excess)
         << " remains, a model error outside the library (a geometry finer than the mesh, or an effect the "
            "library lacks). The stated std"
         << (static_cast<std::size_t>(claimed) + 1 < d.path.size()
                 ? " includes how far the estimate moved in the later fits, but"
                 : "")
         << " cannot include the bias such an error gives every fit alike: the value is the effect that "
            "best mimics the data in this model (on truths from a finer mesh, 2-31% off).";
    if (static_cast<std::size_t>(claimed) < d.claims.size()) {
      const ClaimCheck& next = d.claims[static_cast<std::size_t>(claimed)];
      text << " Not claimed: " << next.effect << " (" << next.reason << ")";
      for (std::size_t j = static_cast<std::size_t>(claimed) + 1; j < d.misfit.effects.size(); ++j)
        text << ", " << d.misfit.effects[j];
      text << '.';
    }
  } else {
    text << "The residual stays unexplained: ";
    if (d.path.size() == 1) {
      text << "no candidate effect (" << (library.empty() ? "none" : "");
      for (std::size_t j = 0; j < library.size(); ++j) text << (j ? ", " : "") << library[j];
      text << ") raised the likelihood by more than its penalty.";
    } else {
      text << "the effects tried (";
      for (std::size_t j = 0; j < after.estimates.size(); ++j)
        text << (j ? ", " : "") << describe_estimate(after.estimates[j]);
      text << ") raise the likelihood but leave the residual inconsistent, so none is claimed";
      if (!d.claims.empty()) text << " (" << d.claims[0].effect << ": " << d.claims[0].reason << ")";
      if (std::isfinite(d.misfit.remaining)) {
        text << "; of the declared model's misfit (mean NIS " << significant_digits(d.before().residual.nis.mean, 4)
             << " against " << significant_digits(d.before().residual.nis.mean_dof, 3) << " observed rows) ";
        for (std::size_t j = 0; j < d.misfit.removed.size(); ++j)
          text << (j ? ", then " : "") << d.misfit.effects[j] << " accounted for " << percent(d.misfit.removed[j]);
        text << ", and " << percent(d.misfit.remaining) << " remains";
      }
      text << ": the data hold an effect outside the library (or more than one).";
    }
  }
  text << " Failed tests: ";
  const std::vector<std::string> failed = after.residual.verdict.failed();
  for (std::size_t j = 0; j < failed.size(); ++j) text << (j ? ", " : "") << failed[j];
  text << '.';
  return text.str();
}

}  // namespace sigmafem
