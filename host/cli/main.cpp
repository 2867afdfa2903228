// sigmafem command line. Exit codes: 0 success, 1 a run that failed (the simulation), 2 bad
// input (files, scenario, options), 3 a device that cannot run it (no OpenCL platform or
// Vulkan driver, a kernel or shader that fails to build or load, out of device memory),
// with a message on stderr that says where and what; 128 + N after signal N (SIGINT,
// SIGTERM, SIGHUP), with the run's staging files removed. Under `mpirun -n R` (R > 1) only
// `estimate` runs (host/mpi/), every rank ending with the same code and a message.
#include <CLI/CLI.hpp>
#include <iostream>
#include <map>

#include "host/cli/commands.h"
#include "host/common/device_error.h"
#include "host/common/input_error.h"
#include "host/common/interruption.h"
#include "host/mpi/ranks.h"

namespace {

// One line on stderr, in one write: the ranks of an MPI run share the terminal, and a line
// written piece by piece could interleave with another rank's.
void report(const std::string& line) { std::cerr << line + "\n" << std::flush; }

// The command's exit code, with every error reported on stderr as the header says.
int run_command(CLI::App& app, std::map<CLI::App*, sigmafem::cli::Action>& actions) {
  const std::string name = sigmafem::program_name();
  try {
    for (CLI::App* sub : app.get_subcommands()) {
      if (sigmafem::ranks().distributed() && sub->get_name() != "estimate")
        throw sigmafem::InputError(sub->get_name() + " runs on one process; over MPI ranks only estimate runs");
      return actions.at(sub)();
    }
  } catch (const sigmafem::Interrupted& e) {
    report(name + ": " + e.what());
    return 128 + e.signal_number();
  } catch (const sigmafem::InputError& e) {
    report(name + ": error: " + e.what());
    return 2;
  } catch (const sigmafem::DeviceError& e) {
    report(name + ": device error: " + e.what());
    return 3;
  } catch (const std::exception& e) {
    report(name + ": failed: " + e.what());
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    sigmafem::start_ranks(&argc, &argv);
  } catch (const sigmafem::InputError& e) {
    report(std::string("sigmafem: error: ") + e.what());
    return 2;
  }
  struct EndRanks {   // every return below ends MPI where start_ranks started it
    ~EndRanks() { sigmafem::finish_ranks(); }
  } end_ranks;
  CLI::App app{"sigmafem: estimates the stiffness of the ligaments that hold an organ from "
               "tracked surface points, with an ensemble reduced-order unscented Kalman filter"};
  app.set_version_flag("--version", std::string("sigmafem ") + SIGMAFEM_VERSION);
  app.require_subcommand(1);
  std::map<CLI::App*, sigmafem::cli::Action> actions;
  for (auto add : {sigmafem::cli::add_generate_command, sigmafem::cli::add_estimate_command,
                   sigmafem::cli::add_diagnose_command,
                   sigmafem::cli::add_demo_command, sigmafem::cli::add_info_command,
                   sigmafem::cli::add_devices_command}) {
    const std::size_t before = app.get_subcommands({}).size();
    sigmafem::cli::Action action = add(app);
    actions[app.get_subcommands({}).at(before)] = std::move(action);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  sigmafem::install_interruption_handlers();
  return run_command(app, actions);
}
