#include "host/engine/make_ensemble.h"

#include "host/common/input_error.h"
#include "host/engine/choose_backend.h"
#include "host/ensemble/cpu_ensemble.h"
#include "host/model/effects.h"
#include "host/opencl/opencl_ensemble.h"
#include "host/reference/nested_multigrid.h"
#include "host/vulkan/vulkan_ensemble.h"

namespace sigmafem {

std::vector<std::string> available_backends() { return {"cpu", "opencl", "vulkan"}; }

std::unique_ptr<SimulationEnsemble> make_ensemble(const std::string& backend, const Model& model,
                                                  const EstimatedParameters& estimated,
                                                  const ObservedPoints& observed, int sigma_count,
                                                  const DeviceOptions& options) {
  if (backend == "auto")
    return make_ensemble(resolve_backend(backend, model, sigma_count, estimated).backend, model, estimated,
                         observed, sigma_count, options);
  if (backend == "cpu" && options.preconditioner == Preconditioner::multigrid)
    throw InputError("--preconditioner multigrid: OpenCL's GPU kernels have it (--backend opencl); the "
                     "cpu back end has its sparse Cholesky factors (factorised)");
  if (backend == "cpu")
    return std::make_unique<CpuEnsemble>(model, estimated, observed, sigma_count, options.cpu_threads,
                                         options.preconditioner);
  if (backend == "opencl")
    return std::make_unique<OpenClEnsemble>(model, estimated, observed, sigma_count, options);
  if (backend == "vulkan")
    return std::make_unique<VulkanEnsemble>(model, estimated, observed, sigma_count, options);
  std::string names;
  for (const std::string& name : available_backends()) names += (names.empty() ? "" : ", ") + name;
  throw InputError("--backend " + backend + ": unknown back end (available: " + names + ")");
}

namespace {

// The type of device `index` among `devices` ("" where there is none).
template <class DeviceInfo>
std::string device_type(const std::vector<DeviceInfo>& devices, int index) {
  return index >= 0 && index < static_cast<int>(devices.size()) ? devices[static_cast<std::size_t>(index)].type
                                                                 : "";
}

}  // namespace

std::string preconditioner_used(const std::string& backend, const DeviceOptions& options, const Model& model) {
  bool factors = false;
  if (backend == "cpu") factors = options.preconditioner != Preconditioner::jacobi;
  if (backend == "opencl") {
    const bool cpu_form = opencl_cpu_form(options.kernel_form, device_type(list_opencl_devices(), options.device));
    if (opencl_uses_multigrid(options.preconditioner, cpu_form, !nested_prolongations(model).empty()))
      return "multigrid";
    factors = opencl_uses_factor(options.preconditioner, cpu_form);
  }
  if (backend == "vulkan") {
    const std::string type = device_type(list_vulkan_devices(), options.device);
    if (vulkan_uses_multigrid(options.preconditioner, type, !nested_prolongations(model).empty())) return "multigrid";
    factors = vulkan_uses_factor(options.preconditioner, type);
  }
  return factors ? "factorised" : "jacobi";
}

std::unique_ptr<EffectEnsemble> make_effect_ensemble(const std::string& backend, Model model,
                                                     EstimatedParameters estimated,
                                                     const ObservedPoints& observed, int sigma_count,
                                                     const DeviceOptions& options,
                                                     const std::vector<std::string>& effects) {
  for (const std::string& name : effects) {
    const EffectDefinition* definition = find_effect(name);
    // The stiffness is a placeholder: set_parameters gives every sigma point its own.
    if (definition && definition->side == EffectSide::ligament)
      estimated.ligaments.push_back(add_extra_ligament(model, name, 0.0));
  }
  return std::make_unique<EffectEnsemble>(
      make_ensemble(backend, model, estimated, observed, sigma_count, options), effects);
}

}  // namespace sigmafem
