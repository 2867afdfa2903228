#include "host/engine/choose_backend.h"

#include "host/common/device_options.h"
#include "host/opencl/opencl_device.h"
#include "host/reference/spring_correction.h"
#include "host/vulkan/vulkan_device.h"

namespace sigmafem {

GpuPresence find_gpus() {
  GpuPresence gpus;
  const std::vector<OpenClDeviceInfo> opencl = list_opencl_devices();
  if (!opencl.empty() && opencl[0].type == "gpu") gpus.opencl = opencl[0].name;
  if (!opencl.empty() && opencl[0].type == "cpu") gpus.opencl_cpu = opencl[0].name;
  const std::vector<VulkanDeviceInfo> vulkan = list_vulkan_devices();
  if (!vulkan.empty() && vulkan[0].type.find("gpu") != std::string::npos)
    gpus.vulkan = vulkan[0].name;
  return gpus;
}

BackendDecision choose_backend(const GpuPresence& gpus, long long elements, int sigma_count,
                               int estimated_regions, std::size_t spring_rows) {
  const long long pairs = elements * sigma_count;
  const std::string size = std::to_string(elements) + " tetrahedra x " +
                           std::to_string(sigma_count) + " sigma points";
  if (gpus.opencl.empty() && gpus.vulkan.empty()) {
    const std::string bounds = "up to " + std::to_string(kCpuDeviceElements) +
                               " tetrahedra or from " + std::to_string(kCpuDevicePairs) + " pairs";
    const bool own_factors = sigma_count >= kOwnFactorsFromSigmaPoints && pairs <= kOwnFactorPairs;
    if (!gpus.opencl_cpu.empty() && !own_factors && pairs < kCpuDevicePairs && estimated_regions > 0)
      return {"cpu", "auto: no GPU; " + size + " with " + std::to_string(estimated_regions) +
                     " region moduli estimated: the CPU back end's own factors precondition sigma points "
                     "that differ by them better than OpenCL's shared one"};
    if (!gpus.opencl_cpu.empty() && (elements <= kCpuDeviceElements || pairs >= kCpuDevicePairs))
      return {"opencl", "auto: no GPU; " + size + " on the CPU device " + gpus.opencl_cpu +
                            ", faster there than the CPU back end (" + bounds + ")"};
    if (!gpus.opencl_cpu.empty() && estimated_regions == 0 && spring_correction_fits(spring_rows, sigma_count))
      return {"opencl", "auto: no GPU; " + size + " on the CPU device " + gpus.opencl_cpu +
                            ", whose shared factor is corrected for each sigma point's springs: faster "
                            "there than the CPU back end"};
    if (!gpus.opencl_cpu.empty())
      return {"cpu", "auto: no GPU; " + size + ": the CPU back end is faster than OpenCL on the "
                     "CPU device between its bounds (" + bounds + ") where OpenCL's shared factor "
                     "is not corrected for the sigma points' springs"};
    return {"cpu", "auto: no GPU; the CPU back end is the fastest without one"};
  }
  if (pairs < kGpuPairs)
    return {"cpu", "auto: " + size + " is too small for the GPU to pay (from " +
                       std::to_string(kGpuPairs) + " pairs)"};
  if (!gpus.opencl.empty()) return {"opencl", "auto: " + size + " on the GPU " + gpus.opencl};
  return {"vulkan", "auto: " + size + " on the GPU " + gpus.vulkan};
}

BackendDecision resolve_backend(const std::string& backend, const Model& model, int sigma_count,
                                const EstimatedParameters& estimated) {
  if (backend != "auto") return {backend, "given"};
  return choose_backend(find_gpus(), model.element_count(), sigma_count,
                        static_cast<int>(estimated.regions.size()),
                        estimated_spring_rows(model, estimated).size());
}

}  // namespace sigmafem
