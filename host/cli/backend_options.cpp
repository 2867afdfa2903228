#include "host/cli/backend_options.h"

#include "host/engine/make_ensemble.h"

namespace sigmafem::cli {

DeviceOptions BackendChoice::device_options() const {
  DeviceOptions options;
  options.device = device;
  options.precision = precision == "double" ? Precision::double_precision : Precision::single;
  options.preconditioner = preconditioner == "jacobi"       ? Preconditioner::jacobi
                           : preconditioner == "factorised" ? Preconditioner::factorised
                           : preconditioner == "multigrid"  ? Preconditioner::multigrid
                                                            : Preconditioner::automatic;
  options.device_memory = device_memory_mib << 20;
  return options;
}

void add_backend_options(CLI::App* command, BackendChoice& choice) {
  std::vector<std::string> names = available_backends();
  names.insert(names.begin(), "auto");
  command->add_option("--backend", choice.backend,
                      "Where the simulations run: cpu (the double-precision reference), a "
                      "device back end, or auto (a GPU where one is there and the ensemble is "
                      "large enough to pay, else OpenCL on a CPU device where it is faster than "
                      "cpu, else cpu; the first line of output says which)")
      ->check(CLI::IsMember(names))
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
                      "CG's preconditioner: jacobi, factorised (sparse Cholesky factors: on cpu one "
                      "per sigma point or one they share, on OpenCL's and Vulkan's CPU devices one "
                      "they share; not on a GPU), multigrid (a V-cycle on the meshes of mesh.refine: "
                      "OpenCL's GPU form and Vulkan) or auto (factorised on cpu and on a CPU device, "
                      "multigrid on a GPU where the mesh was refined, else jacobi)")
      ->check(CLI::IsMember({"auto", "jacobi", "factorised", "multigrid"}))
      ->capture_default_str();
  command->add_option("--device-memory", choice.device_memory_mib,
                      "The most memory a device back end may take, in MiB, where less than the "
                      "device has (a GPU shared with other work); 0: what the device has. An "
                      "ensemble that needs more is refused (exit code 3)")
      ->check(CLI::Range(std::size_t{0}, std::size_t{1} << 40))
      ->capture_default_str();
}

}  // namespace sigmafem::cli
