// What `sigmafem diagnose` writes (docs/FORMATS.md, "Diagnosis"): report.json (every round's
// verdict and candidate scores, the effects chosen with their estimates, the innovation RMS
// and the stiffness error before and after), report.md (the same for a reader),
// residual_before.png and residual_after.png, and, when the residual was explained,
// scenario.json: the scenario with the discovered effects declared, ready for `estimate`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "host/diagnosis/diagnosis.h"

namespace sigmafem::cli {

struct DiagnosisReport {
  std::string data_dir;
  std::string out_dir;
  std::string backend;          // the back end that ran (cpu, opencl, vulkan)
  std::string backend_reason;   // "given", or why --backend auto chose it
  std::string preconditioner;   // CG's: factorised or jacobi
  nlohmann::ordered_json truth_effects;   // truth.json's effects when present, else null
};

// Writes the files atomically and returns report.json's content.
nlohmann::ordered_json write_diagnosis_report(const Scenario& scenario, const Diagnosis& diagnosis,
                                              const DiagnoseOptions& options, const DiagnosisReport& report);

}  // namespace sigmafem::cli
