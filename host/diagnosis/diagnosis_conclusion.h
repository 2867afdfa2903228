// The conclusion of a diagnosis in words (Diagnosis::conclusion, report.md's first paragraph):
// what the outcome is, which effects were added and how much of the misfit each took, what was
// not claimed and why, and which residual tests still fail. Made from the Diagnosis after
// diagnose() has decided everything; it decides nothing.
#pragma once

#include <string>
#include <vector>

#include "host/diagnosis/diagnosis.h"

namespace sigmafem {

// `library`: the candidate effects diagnose tried.
std::string diagnosis_conclusion(const Diagnosis& d, const std::vector<std::string>& library);

// x with `digits` significant digits ("0.123", "1.23e+04"), as the conclusion and the log write.
std::string significant_digits(double x, int digits = 3);

}  // namespace sigmafem
