// The Vulkan devices of this machine and one of them made ready for compute. Discovery
// (`sigmafem devices`), the loader opened at run time and the instances are
// host/vulkan/vulkan_instance.cpp's; VulkanDevice (vulkan_device.cpp) holds a compute queue,
// storage buffers, compute pipelines from the SPIR-V embedded at build time
// (host/vulkan/vulkan_shaders.h), one reusable command buffer and a fence.
//
// Profile: with SIGMAFEM_VULKAN_PROFILE set, every dispatch is timed on the device (timestamp
// queries) and a table of each shader's dispatches and time is printed on stderr when the
// device is released, with the time between them: where the time goes.
//
// Validation: with SIGMAFEM_VULKAN_VALIDATION=1 and VK_LAYER_KHRONOS_validation installed,
// the layer is switched on (with synchronization validation) and every message it sends is
// printed on stderr and counted (vulkan_validation_message_count()), so tests assert none.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "host/common/device_error.h"
#include "host/common/device_options.h"
#include "host/vulkan/spirv_bindings.h"

namespace sigmafem {

struct VulkanDeviceInfo {
  int index = 0;                          // position in vkEnumeratePhysicalDevices' list
  std::string name;
  std::string type;                       // "cpu", "discrete gpu", "integrated gpu", ...
  std::string api_version;                // "1.3.230"
  bool has_fp64 = false;                  // shaderFloat64: --precision double is available
  unsigned long long memory = 0;          // bytes of the largest device-local heap
  unsigned long long max_buffer = 0;      // bytes, the largest storage buffer a shader sees
  unsigned long long max_texel_elements = 0;  // texels, the largest texel buffer view
  // Vulkan 1.1's subgroups (0 and false on a 1.0 device or loader): invocations a subgroup,
  // and whether compute shaders have subgroupShuffle.
  unsigned subgroup_size = 0;
  bool subgroup_shuffle = false;
  // Whether a work-group of `lanes` invocations is one subgroup that shuffles (the shaders'
  // shuffles between a group's lanes: factor_solve_shared, the CG shaders' *_lanes).
  bool shuffles_groups_of(unsigned lanes) const { return subgroup_shuffle && subgroup_size >= lanes; }
};

// Every Vulkan device, in the loader's order. Empty when there is no loader or no driver
// (never an exception for that); `why_none` then says which.
std::vector<VulkanDeviceInfo> list_vulkan_devices(std::string* why_none = nullptr);

// Warnings and errors the validation layer reported in this process so far.
int vulkan_validation_message_count();
// Whether SIGMAFEM_VULKAN_VALIDATION=1 asks for the layer and the layer is installed.
bool vulkan_validation_available();

struct VulkanApi;  // the loader's function table (vulkan_instance.h)

// A buffer in device memory, bound to shaders as a storage buffer, a uniform texel buffer or
// a storage texel buffer (by what each shader declares). Owned by the VulkanDevice that made it.
struct VulkanBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize bytes = 0;
};

// Whether lavapipe (Mesa's CPU Vulkan driver) runs the shaders of the devices enumerated from
// here on on the thread that submits them (serial) or hands each dispatch to its threads, one
// per core (its default): LP_NUM_THREADS, which lavapipe reads when an instance enumerates its
// devices. On a small mesh the hand-over costs more than the threads give back (on a 2-core
// virtual machine about 70 us a dispatch, 1.2 of the liver's 4.3 ms filter step; bench/
// RESULTS.md, stop 55). Left alone where the user set LP_NUM_THREADS (returns false then); no
// effect on other drivers. Not thread-safe (it sets the environment; the choice holds until the
// device's instance has enumerated): devices are made on one thread at a time.
bool choose_lavapipe_threads(bool serial);

// A compute pipeline: one entry shader, `bindings` buffers at bindings 0..n-1 of set 0 (each
// a storage buffer, a uniform texel buffer or a storage texel buffer, as the SPIR-V declares
// it), and 16 bytes of push constants. Owned by the VulkanDevice that made it.
struct VulkanKernel {
  std::string name;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  std::vector<SpirvBinding> kinds;   // each binding's kind, bindings 0..n-1
};

// A device with its queue, ready to run the embedded shaders.
class VulkanDevice {
 public:
  // Throws DeviceError: no loader, no device `index`, no shaderFloat64 for double precision.
  // `lavapipe_serial`: on lavapipe, the shaders on the submitting thread
  // (choose_lavapipe_threads above).
  VulkanDevice(int index, Precision precision, bool lavapipe_serial = false);
  ~VulkanDevice();
  VulkanDevice(const VulkanDevice&) = delete;
  VulkanDevice& operator=(const VulkanDevice&) = delete;

  const VulkanDeviceInfo& info() const { return info_; }
  Precision precision() const { return precision_; }
  std::size_t real_size() const { return sigmafem::real_size(precision_); }
  std::uint32_t max_group_count() const { return max_group_count_; }

  // A device-local buffer of `bytes` (rounded up to whole 8 bytes, at least 8). Throws
  // DeviceError naming `what` when the device has too little memory.
  VulkanBuffer buffer(std::size_t bytes, const char* what);
  void upload(const VulkanBuffer& buffer, const void* data, std::size_t bytes);
  // `values` in this device's precision (to_device_reals); nothing for none.
  void upload_reals(const VulkanBuffer& buffer, const std::vector<double>& values);
  void download(const VulkanBuffer& buffer, void* data, std::size_t bytes);

  // Whether kernel() takes the shaders compiled with texel reads (the kernels made before the
  // call keep their variant). Off by default.
  void set_texel_reads(bool on) { texel_reads_ = on; }
  bool texel_reads() const { return texel_reads_; }

  // The pipeline of embedded shader `name` in this device's precision (and with texel reads
  // when set and the shader has that variant), with specialization constant i set to
  // constants[i] (none given: the shader's defaults). The CG and factor shaders take their
  // work-group size as constant 0, the CG shaders their partitions per sigma point as 1
  // (factor_solve its panels of L) and their rows at once of lanes over sigma points as 2;
  // recenter S and p; element_rhs the rotation method (1 polar). Throws DeviceError when the
  // shader is not embedded, is not SPIR-V or the driver rejects it.
  VulkanKernel kernel(const char* name, int bindings, const std::vector<std::uint32_t>& constants = {});
  // Same, from given SPIR-V words (tests: a module that fails to load).
  VulkanKernel kernel_from_spirv(const std::string& name, const std::uint32_t* words,
                                 std::size_t word_count, int bindings,
                                 const std::vector<std::uint32_t>& constants = {});
  // A descriptor set with `buffers` at bindings 0..n-1 for `kernel`; a texel binding gets a
  // view of its buffer (made once per buffer and format). Throws DeviceError when a buffer
  // bound as texels holds more than the device's maxTexelBufferElements.
  VkDescriptorSet bind(const VulkanKernel& kernel, const std::vector<VulkanBuffer>& buffers);

  // Recording into the device's one reusable command buffer: begin(), then dispatches,
  // barriers, copies; then submit_and_wait() (one host wait).
  VkCommandBuffer begin();
  void dispatch(VkCommandBuffer cmd, const VulkanKernel& kernel, VkDescriptorSet set,
                const void* push_constants, std::uint32_t groups);
  // Every earlier shader write and transfer is visible to every later shader and transfer.
  void barrier(VkCommandBuffer cmd);
  void update(VkCommandBuffer cmd, const VulkanBuffer& buffer, const void* data, std::size_t bytes);
  // `values` in this device's precision, recorded as update() does.
  void update_reals(VkCommandBuffer cmd, const VulkanBuffer& buffer, const std::vector<double>& values);
  // Makes the host-visible read-back area at least `bytes` long (before recording copies).
  void reserve_read_back(std::size_t bytes);
  // Copies `bytes` of `buffer` into the read-back area at `offset` (after a barrier);
  // read_back() gives the area after submit_and_wait().
  void copy_to_host(VkCommandBuffer cmd, const VulkanBuffer& buffer, std::size_t bytes,
                    std::size_t offset);
  const void* read_back() const;
  void submit_and_wait(VkCommandBuffer cmd);

  static constexpr std::size_t kPushConstantBytes = 16;

 private:
  void release();   // every Vulkan object, in reverse order of creation
  std::uint32_t memory_type(std::uint32_t allowed, VkMemoryPropertyFlags wanted,
                            VkMemoryPropertyFlags preferred) const;
  VkDeviceMemory allocate(VkMemoryRequirements needs, VkMemoryPropertyFlags wanted,
                          VkMemoryPropertyFlags preferred, const char* what);
  void check(VkResult result, const std::string& what) const;

  std::shared_ptr<VulkanApi> api_;
  VulkanDeviceInfo info_;
  Precision precision_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  std::uint32_t max_group_count_ = 65535;
  VkCommandPool command_pool_ = VK_NULL_HANDLE;
  VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool_ = VK_NULL_HANDLE;
  std::vector<std::pair<VkBuffer, VkDeviceMemory>> buffers_;   // all buffers made here
  std::vector<VulkanKernel> kernels_;                          // all pipelines made here
  struct TexelView {
    VkBuffer buffer;
    VkFormat format;
    VkBufferView view;
  };
  std::vector<TexelView> views_;                               // all texel views made here
  VkBufferView texel_view(const VulkanBuffer& buffer, SpirvBinding kind, const std::string& kernel);
  bool texel_reads_ = false;
  // Host-visible buffers, mapped for their lifetime: staging for upload/download, and the
  // read-back area.
  struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* map = nullptr;
    std::size_t bytes = 0;
  };
  // Makes `host` at least `bytes` long (a new buffer if it is shorter; its contents go).
  void grow(HostBuffer& host, std::size_t bytes, VkBufferUsageFlags usage, const char* what);
  void destroy(HostBuffer& host);
  // Records a copy of `bytes` of `from` into `to` at `offset`, between the barriers that make
  // the shaders' writes visible to the copy and the copy visible to the host.
  void copy_for_host(VkCommandBuffer cmd, const VulkanBuffer& from, const HostBuffer& to, std::size_t offset,
                     std::size_t bytes);
  HostBuffer staging_;
  HostBuffer read_back_;

  // SIGMAFEM_VULKAN_PROFILE: a timestamp before and after each dispatch of a command buffer
  // (up to kProfiledDispatches of them), read after its wait.
  static constexpr std::uint32_t kProfiledDispatches = 4096;
  VkQueryPool profile_queries_ = VK_NULL_HANDLE;
  double timestamp_seconds_ = 0.0;                   // seconds per timestamp tick
  std::vector<std::string> profiled_;                // the shaders of this command buffer's dispatches
  struct KernelTime {
    double seconds = 0.0;
    long long dispatches = 0;
  };
  std::map<std::string, KernelTime> profile_;
  double profile_between_ = 0.0;                     // seconds between a submission's dispatches
  void collect_profile();
  void print_profile() const;
};

// The name of a VkResult ("VK_ERROR_OUT_OF_DEVICE_MEMORY"), for messages.
std::string vulkan_result_name(VkResult result);

}  // namespace sigmafem
