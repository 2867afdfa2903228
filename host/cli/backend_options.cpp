#include "host/cli/backend_options.h"

#include "host/ensemble/make_ensemble.h"

namespace sigmafem::cli {

DeviceOptions BackendChoice::device_options() const {
  DeviceOptions options;
  options.device = device;
  options.precision = precision == "double" ? Precision::double_precision : Precision::single;
  options.preconditioner = preconditioner == "jacobi"       ? Preconditioner::jacobi
                           : preconditioner == "factorised" ? Preconditioner::factorised
                                                            : Preconditioner::automatic;
  return options;
}

void add_backend_options(CLI::App* command, BackendChoice& choice) {
  command->add_option("--backend", choice.backend,
                      "Where the simulations run: cpu (the double-precision reference) or a "
                      "device back end")
      ->check(CLI::IsMember(available_backends()))
      ->capture_default_str();
  command->add_option("--device", choice.device,
                      "Device index for a device back end (see `sigmafem devices`)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command->add_option("--precision", choice.precision,
                      "Arithmetic of a device back end (double needs the device's fp64)")
      ->check(CLI::IsMember({"single", "double"}))
      ->capture_default_str();
  command->add_option("--preconditioner", choice.preconditioner,
                      "CG's preconditioner: jacobi, factorised (sparse Cholesky factors, one per "
                      "sigma point or one they share; cpu back end only) or auto (factorised on "
                      "cpu, jacobi on the devices)")
      ->check(CLI::IsMember({"auto", "jacobi", "factorised"}))
      ->capture_default_str();
}

}  // namespace sigmafem::cli
