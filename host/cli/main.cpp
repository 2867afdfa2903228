// sigmafem command line. Exit codes: 0 success, 1 a run that failed (the simulation), 2 bad
// input (files, scenario, options), 3 a device that cannot run it (no OpenCL platform or
// Vulkan driver, a kernel or shader that fails to build or load, out of device memory),
// with a message on stderr that says where and what; 128 + N after signal N (SIGINT,
// SIGTERM, SIGHUP), with the run's staging files removed.
#include <CLI/CLI.hpp>
#include <iostream>
#include <map>

#include "host/cli/commands.h"
#include "host/common/device_error.h"
#include "host/common/input_error.h"
#include "host/common/interruption.h"

int main(int argc, char** argv) {
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
  try {
    for (CLI::App* sub : app.get_subcommands()) return actions.at(sub)();
  } catch (const sigmafem::Interrupted& e) {
    std::cerr << "sigmafem: " << e.what() << '\n';
    return 128 + e.signal_number();
  } catch (const sigmafem::InputError& e) {
    std::cerr << "sigmafem: error: " << e.what() << '\n';
    return 2;
  } catch (const sigmafem::DeviceError& e) {
    std::cerr << "sigmafem: device error: " << e.what() << '\n';
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "sigmafem: failed: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
