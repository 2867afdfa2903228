// Short end-of-run summaries printed by the subcommands.
#pragma once

#include <ostream>

#include "host/generator/generate.h"
#include "host/scenario/scenario.h"

namespace sigmafem::cli {

void print_generate_summary(std::ostream& out, const Scenario& scenario,
                            const GenerateOptions& options, const GenerateResult& result);

}  // namespace sigmafem::cli
