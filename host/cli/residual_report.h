// The residual diagnostics of a run as `sigmafem estimate` writes them (docs/FORMATS.md):
// residual.json (every statistic, the tests and the verdict) and residual.png (NIS per step
// against its chi-square band, and the standardised innovations of every row over time).
// A later `diagnose` reads the same JSON shape.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "filter/residual_diagnostics.h"

namespace sigmafem::cli {

// The whole diagnostics as JSON (innovations in mm, rotations in mrad).
// `value` as JSON, null when it is not finite (JSON has no NaN or infinity); the reports' numbers.
nlohmann::ordered_json finite_number(double value);

nlohmann::ordered_json residual_json(const ResidualDiagnostics& diagnostics,
                                     const ResidualDiagnosticsOptions& options);

// Draws residual.png through gnuplot; throws std::runtime_error when gnuplot fails.
void plot_residuals(const ResidualDiagnostics& diagnostics, const InnovationSeries& series,
                    const std::string& title, const std::string& png_path);

}  // namespace sigmafem::cli
