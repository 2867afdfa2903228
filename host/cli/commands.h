// The subcommands of the `sigmafem` program. Each registers its options on the CLI11 app and
// runs when selected; each lives in its own file (<name>_command.cpp).
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace sigmafem::cli {

// A registered subcommand's action: returns the process exit code.
using Action = std::function<int()>;

Action add_generate_command(CLI::App& app);
Action add_estimate_command(CLI::App& app);
Action add_diagnose_command(CLI::App& app);
Action add_demo_command(CLI::App& app);
Action add_info_command(CLI::App& app);
Action add_devices_command(CLI::App& app);

}  // namespace sigmafem::cli
