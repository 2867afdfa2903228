#include "host/vulkan/vulkan_device.h"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>

#include "host/vulkan/vulkan_shaders.h"

namespace sigmafem {

// The Vulkan functions the back end calls, loaded from libvulkan.so.1 at run time (not
// linked): a machine without the loader gets a DeviceError, not a program that cannot start.
#define SF_VULKAN_GLOBAL_FUNCTIONS(X) \
  X(vkCreateInstance)                 \
  X(vkEnumerateInstanceLayerProperties)
#define SF_VULKAN_INSTANCE_FUNCTIONS(X)      \
  X(vkDestroyInstance)                       \
  X(vkEnumeratePhysicalDevices)              \
  X(vkGetPhysicalDeviceProperties)           \
  X(vkGetPhysicalDeviceFeatures)             \
  X(vkGetPhysicalDeviceMemoryProperties)     \
  X(vkGetPhysicalDeviceQueueFamilyProperties) \
  X(vkCreateDevice)                          \
  X(vkDestroyDevice)                         \
  X(vkGetDeviceQueue)                        \
  X(vkCreateBuffer)                          \
  X(vkDestroyBuffer)                         \
  X(vkGetBufferMemoryRequirements)           \
  X(vkAllocateMemory)                        \
  X(vkFreeMemory)                            \
  X(vkBindBufferMemory)                      \
  X(vkMapMemory)                             \
  X(vkCreateShaderModule)                    \
  X(vkDestroyShaderModule)                   \
  X(vkCreateDescriptorSetLayout)             \
  X(vkDestroyDescriptorSetLayout)            \
  X(vkCreatePipelineLayout)                  \
  X(vkDestroyPipelineLayout)                 \
  X(vkCreateComputePipelines)                \
  X(vkDestroyPipeline)                       \
  X(vkCreateDescriptorPool)                  \
  X(vkDestroyDescriptorPool)                 \
  X(vkAllocateDescriptorSets)                \
  X(vkUpdateDescriptorSets)                  \
  X(vkCreateCommandPool)                     \
  X(vkDestroyCommandPool)                    \
  X(vkAllocateCommandBuffers)                \
  X(vkBeginCommandBuffer)                    \
  X(vkEndCommandBuffer)                      \
  X(vkResetCommandBuffer)                    \
  X(vkCmdBindPipeline)                       \
  X(vkCmdBindDescriptorSets)                 \
  X(vkCmdPushConstants)                      \
  X(vkCmdDispatch)                           \
  X(vkCmdPipelineBarrier)                    \
  X(vkCmdCopyBuffer)                         \
  X(vkCmdUpdateBuffer)                       \
  X(vkQueueSubmit)                           \
  X(vkCreateFence)                           \
  X(vkDestroyFence)                          \
  X(vkWaitForFences)                         \
  X(vkResetFences)                           \
  X(vkDeviceWaitIdle)

struct VulkanApi {
  void* library = nullptr;
  PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
#define SF_DECLARE(name) PFN_##name name = nullptr;
  SF_VULKAN_GLOBAL_FUNCTIONS(SF_DECLARE)
  SF_VULKAN_INSTANCE_FUNCTIONS(SF_DECLARE)
#undef SF_DECLARE
  PFN_vkCreateDebugUtilsMessengerEXT vkCreateDebugUtilsMessengerEXT = nullptr;
  PFN_vkDestroyDebugUtilsMessengerEXT vkDestroyDebugUtilsMessengerEXT = nullptr;

  // Loads the instance-level functions (device functions too, through the loader's
  // trampolines) for `instance`.
  void load(VkInstance instance) {
#define SF_LOAD(name) name = reinterpret_cast<PFN_##name>(vkGetInstanceProcAddr(instance, #name));
    SF_VULKAN_INSTANCE_FUNCTIONS(SF_LOAD)
#undef SF_LOAD
    vkCreateDebugUtilsMessengerEXT = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    vkDestroyDebugUtilsMessengerEXT = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
  }
};

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
std::atomic<int> validation_messages{0};

// One instance held for the whole process, never destroyed, so that the loader keeps the
// drivers loaded between devices: it unloads them with the last instance, and Mesa's
// one-time initialisation (pthread_once) would then be redone for every ensemble and leave
// its allocations to LeakSanitizer in a module that no longer exists.
void keep_drivers_loaded(const VulkanApi& api) {
  static const bool held = [&api] {
    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.apiVersion = VK_API_VERSION_1_0;
    VkInstanceCreateInfo create{};
    create.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    create.pApplicationInfo = &app;
    static VkInstance instance = VK_NULL_HANDLE;
    return api.vkCreateInstance(&create, nullptr, &instance) == VK_SUCCESS;
  }();
  (void)held;
}

// The loader, or null with `why` set. Each instance gets its own table (function pointers
// from vkGetInstanceProcAddr belong to their instance).
std::shared_ptr<VulkanApi> open_loader(std::string& why) {
  auto api = std::make_shared<VulkanApi>();
  // Opened once and never closed: the loader and the drivers it loads stay for the whole
  // process (closing them would unload Mesa under live allocations of its own, which
  // LeakSanitizer then reports from an unknown module that no suppression can name).
  static void* const library = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
  api->library = library;
  if (!api->library) {
    why = "no Vulkan loader (libvulkan.so.1) found: install it and a driver (on Debian, "
          "apt-get install libvulkan1 mesa-vulkan-drivers for lavapipe on the CPU) or use "
          "another --backend";
    return nullptr;
  }
  api->vkGetInstanceProcAddr =
      reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(api->library, "vkGetInstanceProcAddr"));
  if (!api->vkGetInstanceProcAddr) {
    why = "libvulkan.so.1 has no vkGetInstanceProcAddr: not a Vulkan loader";
    return nullptr;
  }
#define SF_LOAD_GLOBAL(name) \
  api->name = reinterpret_cast<PFN_##name>(api->vkGetInstanceProcAddr(VK_NULL_HANDLE, #name));
  SF_VULKAN_GLOBAL_FUNCTIONS(SF_LOAD_GLOBAL)
#undef SF_LOAD_GLOBAL
  if (!api->vkCreateInstance || !api->vkEnumerateInstanceLayerProperties) {
    why = "the Vulkan loader lacks vkCreateInstance";
    return nullptr;
  }
  keep_drivers_loaded(*api);
  return api;
}

bool validation_requested() {
  const char* value = std::getenv("SIGMAFEM_VULKAN_VALIDATION");
  return value != nullptr && std::string(value) == "1";
}

bool layer_present(const VulkanApi& api, const char* name) {
  std::uint32_t count = 0;
  if (api.vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (api.vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  return std::any_of(layers.begin(), layers.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  ++validation_messages;
  static std::mutex print;
  std::lock_guard<std::mutex> lock(print);
  std::cerr << "Vulkan validation "
            << (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning")
            << ": " << (data && data->pMessage ? data->pMessage : "(no message)") << "\n";
  return VK_FALSE;
}

struct Instance {
  std::shared_ptr<VulkanApi> api;
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
};

// An instance (no surface extensions: compute only), with the validation layer and its
// messenger when asked for and installed. Null instance with `why` set when there is none.
Instance create_instance(std::string& why, bool with_validation) {
  Instance result;
  result.api = open_loader(why);
  if (!result.api) return result;
  VulkanApi& api = *result.api;
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "sigmafem";
  app.apiVersion = VK_API_VERSION_1_0;
  VkInstanceCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  create.pApplicationInfo = &app;
  const bool validation = with_validation && validation_requested() &&
                          layer_present(api, kValidationLayer);
  const char* layers[] = {kValidationLayer};
  const char* extensions[] = {VK_EXT_DEBUG_UTILS_EXTENSION_NAME};
  VkDebugUtilsMessengerCreateInfoEXT messenger{};
  messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = on_validation_message;
  // Synchronization validation too: a missing barrier between dispatches is a race that
  // the conformance tests could pass by luck on one driver.
  VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{};
  features.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  features.pNext = &messenger;   // messages from vkCreateInstance itself
  if (validation) {
    create.enabledLayerCount = 1;
    create.ppEnabledLayerNames = layers;
    create.enabledExtensionCount = 1;
    create.ppEnabledExtensionNames = extensions;
    create.pNext = &features;
  }
  const VkResult made = api.vkCreateInstance(&create, nullptr, &result.instance);
  if (made != VK_SUCCESS) {
    result.instance = VK_NULL_HANDLE;
    why = made == VK_ERROR_INCOMPATIBLE_DRIVER
              ? "no Vulkan driver found: install one (on Debian, lavapipe for the CPU: "
                "apt-get install mesa-vulkan-drivers) or use another --backend"
              : "creating a Vulkan instance failed with " + vulkan_result_name(made);
    return result;
  }
  api.load(result.instance);
  if (validation && api.vkCreateDebugUtilsMessengerEXT) {
    messenger.pNext = nullptr;
    if (api.vkCreateDebugUtilsMessengerEXT(result.instance, &messenger, nullptr,
                                           &result.messenger) != VK_SUCCESS)
      result.messenger = VK_NULL_HANDLE;
  }
  return result;
}

void destroy_instance(Instance& instance) {
  if (!instance.instance) return;
  if (instance.messenger) instance.api->vkDestroyDebugUtilsMessengerEXT(instance.instance, instance.messenger, nullptr);
  instance.api->vkDestroyInstance(instance.instance, nullptr);
  instance.instance = VK_NULL_HANDLE;
}

std::string device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete gpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual gpu";
    default: return "other";
  }
}

std::vector<VkPhysicalDevice> physical_devices(const Instance& instance) {
  std::uint32_t count = 0;
  if (instance.api->vkEnumeratePhysicalDevices(instance.instance, &count, nullptr) != VK_SUCCESS)
    return {};
  std::vector<VkPhysicalDevice> devices(count);
  if (instance.api->vkEnumeratePhysicalDevices(instance.instance, &count, devices.data()) != VK_SUCCESS)
    return {};
  devices.resize(count);
  return devices;
}

VulkanDeviceInfo describe(const VulkanApi& api, VkPhysicalDevice device, int index) {
  VkPhysicalDeviceProperties properties;
  api.vkGetPhysicalDeviceProperties(device, &properties);
  VkPhysicalDeviceFeatures features;
  api.vkGetPhysicalDeviceFeatures(device, &features);
  VkPhysicalDeviceMemoryProperties memory;
  api.vkGetPhysicalDeviceMemoryProperties(device, &memory);
  VulkanDeviceInfo info;
  info.index = index;
  info.name = properties.deviceName;
  info.type = device_type_name(properties.deviceType);
  info.api_version = std::to_string(VK_VERSION_MAJOR(properties.apiVersion)) + "." +
                     std::to_string(VK_VERSION_MINOR(properties.apiVersion)) + "." +
                     std::to_string(VK_VERSION_PATCH(properties.apiVersion));
  info.has_fp64 = features.shaderFloat64 == VK_TRUE;
  for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h)
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
      info.memory = std::max<unsigned long long>(info.memory, memory.memoryHeaps[h].size);
  info.max_buffer = properties.limits.maxStorageBufferRange;
  return info;
}

const std::string kNoDevice =
    "no Vulkan device found: install a driver (on Debian, lavapipe for the CPU: apt-get "
    "install mesa-vulkan-drivers) or use another --backend";

}  // namespace

int vulkan_validation_message_count() { return validation_messages.load(); }

bool vulkan_validation_available() {
  if (!validation_requested()) return false;
  std::string why;
  const std::shared_ptr<VulkanApi> api = open_loader(why);
  return api && layer_present(*api, kValidationLayer);
}

std::vector<VulkanDeviceInfo> list_vulkan_devices(std::string* why_none) {
  std::string why;
  // Listing needs no validation (and `sigmafem devices` should not print its messages).
  Instance instance = create_instance(why, false);
  std::vector<VulkanDeviceInfo> list;
  if (instance.instance) {
    const std::vector<VkPhysicalDevice> devices = physical_devices(instance);
    for (std::size_t i = 0; i < devices.size(); ++i)
      list.push_back(describe(*instance.api, devices[i], static_cast<int>(i)));
    if (list.empty()) why = kNoDevice;
    destroy_instance(instance);
  }
  if (why_none) *why_none = why;
  return list;
}

std::string vulkan_result_name(VkResult result) {
  switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS: return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_INVALID_SHADER_NV: return "VK_ERROR_INVALID_SHADER_NV";
    default: return "VkResult " + std::to_string(static_cast<int>(result));
  }
}

VulkanDevice::VulkanDevice(int index, Precision precision) : precision_(precision) {
  std::string why;
  Instance instance = create_instance(why, true);
  if (!instance.instance) throw DeviceError(why);
  api_ = instance.api;
  instance_ = instance.instance;
  messenger_ = instance.messenger;
  // The destructor does not run when the constructor throws: release() by hand then.
  try {
    const std::vector<VkPhysicalDevice> devices = physical_devices(instance);
    if (devices.empty()) throw DeviceError(kNoDevice);
    if (index < 0 || index >= static_cast<int>(devices.size()))
      throw DeviceError("no Vulkan device " + std::to_string(index) + ": there are " +
                        std::to_string(devices.size()) + " (see `sigmafem devices`)");
    physical_ = devices[index];
    info_ = describe(*api_, physical_, index);
    if (precision == Precision::double_precision && !info_.has_fp64)
      throw DeviceError("Vulkan device " + std::to_string(index) + " (" + info_.name +
                        ") has no double precision (shaderFloat64); use --precision single");
    api_->vkGetPhysicalDeviceMemoryProperties(physical_, &memory_properties_);
    VkPhysicalDeviceProperties properties;
    api_->vkGetPhysicalDeviceProperties(physical_, &properties);
    max_group_count_ = properties.limits.maxComputeWorkGroupCount[0];

    std::uint32_t family_count = 0;
    api_->vkGetPhysicalDeviceQueueFamilyProperties(physical_, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    api_->vkGetPhysicalDeviceQueueFamilyProperties(physical_, &family_count, families.data());
    bool found = false;
    for (std::uint32_t f = 0; f < family_count && !found; ++f)
      if (families[f].queueFlags & VK_QUEUE_COMPUTE_BIT) {
        queue_family_ = f;
        found = true;
      }
    if (!found) throw DeviceError("Vulkan device " + info_.name + " has no compute queue");

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queue{};
    queue.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    queue.queueFamilyIndex = queue_family_;
    queue.queueCount = 1;
    queue.pQueuePriorities = &priority;
    VkPhysicalDeviceFeatures features{};
    features.shaderFloat64 = precision == Precision::double_precision ? VK_TRUE : VK_FALSE;
    VkDeviceCreateInfo create{};
    create.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    create.queueCreateInfoCount = 1;
    create.pQueueCreateInfos = &queue;
    create.pEnabledFeatures = &features;
    check(api_->vkCreateDevice(physical_, &create, nullptr, &device_), "creating the Vulkan device");
    api_->vkGetDeviceQueue(device_, queue_family_, 0, &queue_);

    VkCommandPoolCreateInfo pool{};
    pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = queue_family_;
    check(api_->vkCreateCommandPool(device_, &pool, nullptr, &command_pool_), "creating a command pool");
    VkCommandBufferAllocateInfo allocate{};
    allocate.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate.commandPool = command_pool_;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = 1;
    check(api_->vkAllocateCommandBuffers(device_, &allocate, &command_buffer_),
          "allocating a command buffer");
    VkFenceCreateInfo fence{};
    fence.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    check(api_->vkCreateFence(device_, &fence, nullptr, &fence_), "creating a fence");

    // Enough for the ensemble's descriptor sets (about twenty, at most 25 buffers each; about
    // 240 buffers in all).
    VkDescriptorPoolSize sizes{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1024};
    VkDescriptorPoolCreateInfo descriptors{};
    descriptors.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    descriptors.maxSets = 64;
    descriptors.poolSizeCount = 1;
    descriptors.pPoolSizes = &sizes;
    check(api_->vkCreateDescriptorPool(device_, &descriptors, nullptr, &descriptor_pool_),
          "creating a descriptor pool");

    reserve_read_back(4096);
  } catch (...) {
    release();
    throw;
  }
}

VulkanDevice::~VulkanDevice() { release(); }

void VulkanDevice::release() {
  if (device_) {
    api_->vkDeviceWaitIdle(device_);
    for (const VulkanKernel& k : kernels_) {
      api_->vkDestroyPipeline(device_, k.pipeline, nullptr);
      api_->vkDestroyPipelineLayout(device_, k.layout, nullptr);
      api_->vkDestroyDescriptorSetLayout(device_, k.set_layout, nullptr);
    }
    kernels_.clear();
    for (const auto& [buffer, memory] : buffers_) {
      api_->vkDestroyBuffer(device_, buffer, nullptr);
      api_->vkFreeMemory(device_, memory, nullptr);
    }
    buffers_.clear();
    destroy(staging_);
    destroy(read_back_);
    if (descriptor_pool_) api_->vkDestroyDescriptorPool(device_, descriptor_pool_, nullptr);
    if (fence_) api_->vkDestroyFence(device_, fence_, nullptr);
    if (command_pool_) api_->vkDestroyCommandPool(device_, command_pool_, nullptr);
    api_->vkDestroyDevice(device_, nullptr);
    device_ = VK_NULL_HANDLE;
  }
  if (instance_) {
    if (messenger_) api_->vkDestroyDebugUtilsMessengerEXT(instance_, messenger_, nullptr);
    api_->vkDestroyInstance(instance_, nullptr);
    instance_ = VK_NULL_HANDLE;
  }
}

void VulkanDevice::check(VkResult result, const std::string& what) const {
  if (result == VK_SUCCESS) return;
  std::string message = what + " failed with " + vulkan_result_name(result);
  if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY || result == VK_ERROR_OUT_OF_HOST_MEMORY)
    message += " (out of device memory: use fewer sigma points, a coarser mesh or another device)";
  throw DeviceError("Vulkan on " + (info_.name.empty() ? std::string("the device") : info_.name) +
                    ": " + message);
}

std::uint32_t VulkanDevice::memory_type(std::uint32_t allowed, VkMemoryPropertyFlags wanted,
                                        VkMemoryPropertyFlags preferred) const {
  int best = -1;
  for (std::uint32_t t = 0; t < memory_properties_.memoryTypeCount; ++t) {
    const VkMemoryPropertyFlags flags = memory_properties_.memoryTypes[t].propertyFlags;
    if (!(allowed & (1u << t)) || (flags & wanted) != wanted) continue;
    if ((flags & preferred) == preferred) return t;
    if (best < 0) best = static_cast<int>(t);
  }
  if (best < 0) throw DeviceError("Vulkan device " + info_.name + " has no suitable memory type");
  return static_cast<std::uint32_t>(best);
}

VkDeviceMemory VulkanDevice::allocate(VkMemoryRequirements needs, VkMemoryPropertyFlags wanted,
                                      VkMemoryPropertyFlags preferred, const char* what) {
  VkMemoryAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate.allocationSize = needs.size;
  allocate.memoryTypeIndex = memory_type(needs.memoryTypeBits, wanted, preferred);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  check(api_->vkAllocateMemory(device_, &allocate, nullptr, &memory), std::string("allocating ") + what);
  return memory;
}

VulkanBuffer VulkanDevice::buffer(std::size_t bytes, const char* what) {
  bytes = std::max<std::size_t>(4, (bytes + 3) / 4 * 4);
  if (bytes > info_.max_buffer)
    throw DeviceError(std::string("out of device memory: ") + what + " needs " +
                      std::to_string(bytes >> 20) + " MiB in one buffer; " + info_.name +
                      " allows " + std::to_string(info_.max_buffer >> 20) +
                      " MiB (maxStorageBufferRange). Use fewer sigma points or a coarser mesh");
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = bytes;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VulkanBuffer result;
  result.bytes = bytes;
  check(api_->vkCreateBuffer(device_, &info, nullptr, &result.buffer), std::string("creating ") + what);
  VkMemoryRequirements needs;
  api_->vkGetBufferMemoryRequirements(device_, result.buffer, &needs);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  try {
    memory = allocate(needs, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, what);
    check(api_->vkBindBufferMemory(device_, result.buffer, memory, 0), std::string("binding ") + what);
  } catch (...) {
    api_->vkDestroyBuffer(device_, result.buffer, nullptr);
    if (memory) api_->vkFreeMemory(device_, memory, nullptr);
    throw;
  }
  buffers_.emplace_back(result.buffer, memory);
  return result;
}

void VulkanDevice::destroy(HostBuffer& host) {
  if (host.buffer) api_->vkDestroyBuffer(device_, host.buffer, nullptr);
  if (host.memory) api_->vkFreeMemory(device_, host.memory, nullptr);
  host = HostBuffer{};
}

void VulkanDevice::grow(HostBuffer& host, std::size_t bytes, VkBufferUsageFlags usage,
                        const char* what) {
  if (bytes <= host.bytes) return;
  destroy(host);
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = bytes;
  info.usage = usage;
  check(api_->vkCreateBuffer(device_, &info, nullptr, &host.buffer), std::string("creating ") + what);
  VkMemoryRequirements needs;
  api_->vkGetBufferMemoryRequirements(device_, host.buffer, &needs);
  host.memory = allocate(needs, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                         VK_MEMORY_PROPERTY_HOST_CACHED_BIT, what);
  check(api_->vkBindBufferMemory(device_, host.buffer, host.memory, 0), std::string("binding ") + what);
  check(api_->vkMapMemory(device_, host.memory, 0, VK_WHOLE_SIZE, 0, &host.map),
        std::string("mapping ") + what);
  host.bytes = bytes;
}

void VulkanDevice::upload(const VulkanBuffer& buffer, const void* data, std::size_t bytes) {
  if (bytes == 0) return;
  grow(staging_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
       "a staging buffer");
  std::memcpy(staging_.map, data, bytes);
  VkCommandBuffer cmd = begin();
  VkBufferCopy region{0, 0, bytes};
  api_->vkCmdCopyBuffer(cmd, staging_.buffer, buffer.buffer, 1, &region);
  barrier(cmd);
  submit_and_wait(cmd);
}

void VulkanDevice::download(const VulkanBuffer& buffer, void* data, std::size_t bytes) {
  if (bytes == 0) return;
  grow(staging_, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
       "a staging buffer");
  VkCommandBuffer cmd = begin();
  copy_for_host(cmd, buffer, staging_, 0, bytes);
  submit_and_wait(cmd);
  std::memcpy(data, staging_.map, bytes);
}

VulkanKernel VulkanDevice::kernel(const char* name, int bindings, std::uint32_t group_size,
                                  std::uint32_t partitions) {
  const bool want_double = precision_ == Precision::double_precision;
  for (std::size_t i = 0; i < kVulkanShaderCount; ++i) {
    const EmbeddedShader& shader = kVulkanShaders[i];
    if (shader.double_precision == want_double && std::strcmp(shader.name, name) == 0)
      return kernel_from_spirv(name, shader.words, shader.word_count, bindings, group_size,
                               partitions);
  }
  throw DeviceError(std::string("no embedded Vulkan shader '") + name + "' (" +
                    (want_double ? "double" : "single") +
                    " precision): the build did not compile it from kernels/vulkan/");
}

VulkanKernel VulkanDevice::kernel_from_spirv(const std::string& name, const std::uint32_t* words,
                                             std::size_t word_count, int bindings,
                                             std::uint32_t group_size, std::uint32_t partitions) {
  // Drivers may crash on a module that is not SPIR-V, so look at its header first.
  constexpr std::uint32_t kSpirvMagic = 0x07230203;
  if (word_count < 5 || words == nullptr || words[0] != kSpirvMagic)
    throw DeviceError("the Vulkan shader " + name + " failed to load on " + info_.name +
                      ": not a SPIR-V module (bad header); rebuild sigmafem");
  VulkanKernel k;
  k.name = name;
  k.bindings = bindings;
  VkShaderModule module = VK_NULL_HANDLE;
  try {
    std::vector<VkDescriptorSetLayoutBinding> slots(bindings);
    for (int b = 0; b < bindings; ++b) {
      slots[b] = {};
      slots[b].binding = static_cast<std::uint32_t>(b);
      slots[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      slots[b].descriptorCount = 1;
      slots[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo set{};
    set.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    set.bindingCount = static_cast<std::uint32_t>(bindings);
    set.pBindings = slots.data();
    check(api_->vkCreateDescriptorSetLayout(device_, &set, nullptr, &k.set_layout),
          "creating the descriptor set layout of " + name);
    VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, kPushConstantBytes};
    VkPipelineLayoutCreateInfo layout{};
    layout.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layout.setLayoutCount = 1;
    layout.pSetLayouts = &k.set_layout;
    layout.pushConstantRangeCount = 1;
    layout.pPushConstantRanges = &push;
    check(api_->vkCreatePipelineLayout(device_, &layout, nullptr, &k.layout),
          "creating the pipeline layout of " + name);
    VkShaderModuleCreateInfo code{};
    code.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    code.codeSize = word_count * sizeof(std::uint32_t);
    code.pCode = words;
    check(api_->vkCreateShaderModule(device_, &code, nullptr, &module),
          "loading the Vulkan shader " + name);
    // Constant 0 the group size, constant 1 the partitions (when given).
    const std::uint32_t constants[2] = {group_size, partitions};
    const VkSpecializationMapEntry entries[2] = {{0, 0, sizeof(std::uint32_t)},
                                                 {1, sizeof(std::uint32_t), sizeof(std::uint32_t)}};
    VkSpecializationInfo specialization{partitions > 0 ? 2u : 1u, entries, sizeof(constants),
                                        constants};
    VkComputePipelineCreateInfo pipeline{};
    pipeline.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    pipeline.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipeline.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipeline.stage.module = module;
    pipeline.stage.pName = "main";
    pipeline.stage.pSpecializationInfo = group_size > 0 ? &specialization : nullptr;
    pipeline.layout = k.layout;
    check(api_->vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &pipeline, nullptr, &k.pipeline),
          "building the Vulkan shader " + name + " (vkCreateComputePipelines)");
  } catch (...) {
    if (module) api_->vkDestroyShaderModule(device_, module, nullptr);
    if (k.pipeline) api_->vkDestroyPipeline(device_, k.pipeline, nullptr);
    if (k.layout) api_->vkDestroyPipelineLayout(device_, k.layout, nullptr);
    if (k.set_layout) api_->vkDestroyDescriptorSetLayout(device_, k.set_layout, nullptr);
    throw;
  }
  api_->vkDestroyShaderModule(device_, module, nullptr);
  kernels_.push_back(k);
  return k;
}

VkDescriptorSet VulkanDevice::bind(const VulkanKernel& kernel, const std::vector<VulkanBuffer>& buffers) {
  if (static_cast<int>(buffers.size()) != kernel.bindings)
    throw std::logic_error("VulkanDevice::bind: " + kernel.name + " takes " +
                           std::to_string(kernel.bindings) + " buffers, given " +
                           std::to_string(buffers.size()));
  VkDescriptorSetAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  allocate.descriptorPool = descriptor_pool_;
  allocate.descriptorSetCount = 1;
  allocate.pSetLayouts = &kernel.set_layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  check(api_->vkAllocateDescriptorSets(device_, &allocate, &set),
        "allocating the descriptor set of " + kernel.name);
  std::vector<VkDescriptorBufferInfo> infos(buffers.size());
  std::vector<VkWriteDescriptorSet> writes(buffers.size());
  for (std::size_t b = 0; b < buffers.size(); ++b) {
    infos[b] = {buffers[b].buffer, 0, VK_WHOLE_SIZE};
    writes[b] = {};
    writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[b].dstSet = set;
    writes[b].dstBinding = static_cast<std::uint32_t>(b);
    writes[b].descriptorCount = 1;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  api_->vkUpdateDescriptorSets(device_, static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
  return set;
}

VkCommandBuffer VulkanDevice::begin() {
  check(api_->vkResetCommandBuffer(command_buffer_, 0), "resetting the command buffer");
  VkCommandBufferBeginInfo begin_info{};
  begin_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(api_->vkBeginCommandBuffer(command_buffer_, &begin_info), "recording a command buffer");
  return command_buffer_;
}

void VulkanDevice::dispatch(VkCommandBuffer cmd, const VulkanKernel& kernel, VkDescriptorSet set,
                            const void* push_constants, std::uint32_t groups) {
  if (groups == 0) return;
  api_->vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, kernel.pipeline);
  api_->vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, kernel.layout, 0, 1, &set, 0, nullptr);
  api_->vkCmdPushConstants(cmd, kernel.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, kPushConstantBytes,
                           push_constants);
  // Past the device's limit on groups per dimension, a 2-D grid (sf_global_id() flattens it).
  const std::uint32_t x = std::min(groups, max_group_count_);
  const std::uint32_t y = (groups + x - 1) / x;
  api_->vkCmdDispatch(cmd, x, y, 1);
}

void VulkanDevice::barrier(VkCommandBuffer cmd) {
  VkMemoryBarrier memory{};
  memory.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  memory.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  memory.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT |
                         VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  const VkPipelineStageFlags stages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT;
  api_->vkCmdPipelineBarrier(cmd, stages, stages, 0, 1, &memory, 0, nullptr, 0, nullptr);
}

void VulkanDevice::update(VkCommandBuffer cmd, const VulkanBuffer& buffer, const void* data,
                          std::size_t bytes) {
  // vkCmdUpdateBuffer takes at most 65536 bytes at a time.
  constexpr std::size_t kMostPerUpdate = 65536;
  for (std::size_t offset = 0; offset < bytes; offset += kMostPerUpdate)
    api_->vkCmdUpdateBuffer(cmd, buffer.buffer, offset, std::min(kMostPerUpdate, bytes - offset),
                            static_cast<const unsigned char*>(data) + offset);
}

void VulkanDevice::reserve_read_back(std::size_t bytes) {
  grow(read_back_, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, "the read-back buffer");
}

void VulkanDevice::copy_to_host(VkCommandBuffer cmd, const VulkanBuffer& buffer, std::size_t bytes,
                                std::size_t offset) {
  if (offset + bytes > read_back_.bytes)
    throw std::logic_error("VulkanDevice::copy_to_host: read-back area too small");
  copy_for_host(cmd, buffer, read_back_, offset, bytes);
}

void VulkanDevice::copy_for_host(VkCommandBuffer cmd, const VulkanBuffer& from, const HostBuffer& to,
                                 std::size_t offset, std::size_t bytes) {
  barrier(cmd);   // after the shaders' writes
  VkBufferCopy region{0, offset, bytes};
  api_->vkCmdCopyBuffer(cmd, from.buffer, to.buffer, 1, &region);
  VkMemoryBarrier host{};
  host.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  api_->vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                             &host, 0, nullptr, 0, nullptr);
}

const void* VulkanDevice::read_back() const { return read_back_.map; }

void VulkanDevice::submit_and_wait(VkCommandBuffer cmd) {
  check(api_->vkEndCommandBuffer(cmd), "recording a command buffer");
  VkSubmitInfo submit{};
  submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  check(api_->vkQueueSubmit(queue_, 1, &submit, fence_), "submitting to the Vulkan queue");
  check(api_->vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "waiting for the device");
  check(api_->vkResetFences(device_, 1, &fence_), "resetting a fence");
}

}  // namespace sigmafem
