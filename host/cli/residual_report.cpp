#include "host/cli/residual_report.h"

#include <cmath>
#include <sstream>

#include "host/cli/plot.h"
#include "host/data/csv_format.h"

namespace sigmafem::cli {
using json = nlohmann::ordered_json;

namespace {

const char* const kAxes[] = {"x", "y", "z"};

json vector3(const Eigen::Vector3d& v, double scale) {
  return json::array({finite_number(scale * v.x()), finite_number(scale * v.y()), finite_number(scale * v.z())});
}

json row_json(int row) { return {{"row", row}, {"point", row / 3}, {"axis", kAxes[row % 3]}}; }

json test_json(const DiagnosticTest& test) {
  return {{"name", test.name},       {"passed", test.passed},           {"statistic", finite_number(test.statistic)},
          {"accept_low", finite_number(test.accept_low)}, {"accept_high", finite_number(test.accept_high)},
          {"p_value", finite_number(test.p_value)},       {"level", test.level}, {"detail", test.detail}};
}

}  // namespace

json finite_number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

json residual_json(const ResidualDiagnostics& d, const ResidualDiagnosticsOptions& options) {
  json j;
  j["verdict"] = to_string(d.verdict.consistency);
  j["failed_tests"] = d.verdict.failed();
  j["false_alarm"] = options.false_alarm;
  j["burn_in_steps"] = d.burn_in_steps;
  j["steps_used"] = d.steps_used;
  j["catch_up_steps"] = d.catch_up_steps;
  j["first_step"] = d.first_step;
  json tests = json::array();
  for (const DiagnosticTest& test : d.verdict.tests) tests.push_back(test_json(test));
  j["tests"] = tests;
  if (d.verdict.consistency == Consistency::too_few_steps) return j;

  const NisDiagnostics& nis = d.nis;
  j["nis"] = {{"mean", nis.mean},
              {"expected", nis.mean_dof},
              {"accepted", {nis.band_low, nis.band_high}},
              {"band_95", {nis.band95_low, nis.band95_high}},
              {"p_value", nis.p_value},
              {"steps_above_95_band", nis.steps_above},
              {"fraction_above_95_band", nis.fraction_above},
              {"max_above_accepted", nis.max_above}};
  // A few scans of many points: only the NIS tests ran (ResidualDiagnostics::nis_only).
  j["nis_only"] = d.nis_only;
  if (d.nis_only) return j;

  const WhitenessDiagnostics& w = d.whiteness;
  json flagged_white = json::array();
  for (int row : w.flagged_rows) {
    json entry = row_json(row);
    entry["ljung_box"] = w.row_ljung_box[static_cast<std::size_t>(row)];
    entry["p_value"] = w.row_p_value[static_cast<std::size_t>(row)];
    flagged_white.push_back(entry);
  }
  j["whiteness"] = {{"max_lag", w.max_lag},
                    {"autocorrelation", w.autocorrelation},
                    {"band_95", w.band},
                    {"effective_rows", w.effective_rows},
                    {"ljung_box", w.ljung_box},
                    {"p_value", w.p_value},
                    {"row_p_threshold", w.row_p_threshold},
                    {"flagged_rows", flagged_white}};

  const BiasDiagnostics& b = d.bias;
  json rows = json::array();
  for (Eigen::Index i = 0; i < b.mean.size(); ++i) {
    json entry = row_json(static_cast<int>(i));
    entry["count"] = b.count[i];
    entry["mean_mm"] = finite_number(1e3 * b.mean[i]);
    entry["standard_error_mm"] = finite_number(1e3 * b.standard_error[i]);
    entry["t"] = finite_number(b.t[i]);
    entry["t_threshold"] = finite_number(b.t_threshold[i]);
    entry["flagged"] = std::isfinite(b.t[i]) && std::fabs(b.t[i]) > b.t_threshold[i];
    rows.push_back(entry);
  }
  j["bias"] = {{"flagged_rows", b.flagged_rows}, {"rows", rows}};

  const SpatialPattern& s = d.spatial;
  json points = json::array();
  for (Eigen::Index p = 0; p < s.mean_field.rows(); ++p)
    points.push_back({{"point", p},
                      {"mean_mm", vector3(s.mean_field.row(p).transpose(), 1e3)},
                      {"rigid_mm", vector3(s.rigid_field.row(p).transpose(), 1e3)},
                      {"deformation_mm", vector3(s.deformation_field.row(p).transpose(), 1e3)}});
  json component_t = json::object();
  static const char* const names[] = {"translation_x", "translation_y", "translation_z",
                                      "rotation_x",    "rotation_y",    "rotation_z"};
  for (int c = 0; c < 6; ++c) component_t[names[c]] = s.component_t[c];
  j["spatial"] = {{"centroid_m", vector3(s.centroid, 1.0)},
                  {"translation_mm", vector3(s.translation, 1e3)},
                  {"rotation_mrad", vector3(s.rotation, 1e3)},
                  {"total_rms_mm", finite_number(1e3 * s.total_rms)},
                  {"rigid_rms_mm", finite_number(1e3 * s.rigid_rms)},
                  {"deformation_rms_mm", finite_number(1e3 * s.deformation_rms)},
                  {"rigid_share", s.rigid_share},
                  {"component_t", component_t},
                  {"component_t_threshold", s.component_t_threshold},
                  {"points", points}};
  return j;
}

void plot_residuals(const ResidualDiagnostics& d, const InnovationSeries& series, const std::string& title,
                    const std::string& png_path) {
  const Eigen::Index n = series.innovation.cols();
  PlotData data;
  data.columns = {"time", "nis", "band_low", "band_high", "mean_standardised"};
  for (Eigen::Index i = 0; i < n; ++i) data.columns.push_back("row_" + std::to_string(i));
  // The per-step 95% band of each step's own dof (the diagnostics hold it for the steps used).
  std::vector<double> band_low(series.steps.size(), NAN), band_high(series.steps.size(), NAN);
  for (std::size_t u = 0; u < d.used.size() && u < d.nis.step_band_low.size(); ++u) {
    band_low[static_cast<std::size_t>(d.used[u])] = d.nis.step_band_low[u];
    band_high[static_cast<std::size_t>(d.used[u])] = d.nis.step_band_high[u];
  }
  for (std::size_t k = 0; k < series.steps.size(); ++k) {
    const auto kk = static_cast<Eigen::Index>(k);
    const bool observed = series.observed_rows[k] > 0;
    std::vector<double> row = {series.times[k], observed ? series.normalised_innovation[kk] : NAN,
                               band_low[k], band_high[k], NAN};
    double sum = 0.0;
    int count = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double x = series.innovation(kk, i) / series.innovation_std(kk, i);
      row.push_back(std::isfinite(x) ? x : NAN);
      if (std::isfinite(x)) {
        sum += x;
        ++count;
      }
    }
    if (count) row[4] = sum / count;
    data.rows.push_back(row);
  }
  const double burn_in_time =
      d.burn_in_steps > 0 && d.burn_in_steps <= static_cast<int>(series.times.size())
          ? series.times[static_cast<std::size_t>(d.burn_in_steps - 1)]
          : NAN;
  std::ostringstream script;
  script << "set output $output\nset datafile missing 'nan'\nset grid\nset key outside right\n"
         << "set lmargin at screen 0.08\nset rmargin at screen 0.84\n"
         << "set multiplot layout 2,1 title '" << title << ": residual diagnostics, verdict "
         << to_string(d.verdict.consistency) << "'\n";
  if (std::isfinite(burn_in_time))
    script << "set arrow 1 from " << format_number(burn_in_time) << ", graph 0 to "
           << format_number(burn_in_time) << ", graph 1 nohead dt 3 lc rgb '#7f7f7f'\n"
           << "set label 1 'burn-in' at " << format_number(burn_in_time) << ", graph 0.95 right offset -0.5,0\n";
  script << "set ylabel 'NIS z^T S^-1 z'\nset logscale y\nunset xlabel\n"
         << "plot $data using 1:2 with points pt 7 ps 0.4 lc rgb '#1f77b4' title 'NIS', "
         << "$data using 1:3 with lines lw 1.5 lc rgb '#d62728' title '95% band', "
         << "$data using 1:4 with lines lw 1.5 lc rgb '#d62728' notitle\n"
         << "unset logscale y\nset xlabel 'time (s)'\nset ylabel 'z_i / sqrt(S_ii)'\n"
         << "set yrange [-6:6]\n"
         << "plot for [c=6:" << 5 + n << "] $data using 1:c with dots lc rgb '#9fbfdf' notitle, "
         << "$data using 1:5 with lines lw 1.5 lc rgb '#1f77b4' title 'mean over rows', "
         << "1.96 with lines dt 2 lc rgb '#d62728' title '+-1.96', -1.96 with lines dt 2 lc rgb '#d62728' notitle\n"
         << "unset multiplot\n";
  render_plot(data, script.str(), png_path);
}

}  // namespace sigmafem::cli
