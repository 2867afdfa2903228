#include "host/vulkan/vulkan_instance.h"

#include <dlfcn.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <string>
#include <thread>

namespace sigmafem {

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
  api->vkEnumerateInstanceVersion = reinterpret_cast<PFN_vkEnumerateInstanceVersion>(
      api->vkGetInstanceProcAddr(VK_NULL_HANDLE, "vkEnumerateInstanceVersion"));
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

std::string device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete gpu";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated gpu";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual gpu";
    default: return "other";
  }
}

}  // namespace

bool choose_lavapipe_threads(bool serial) {
  static const bool users_own = std::getenv("LP_NUM_THREADS") != nullptr;   // before any set here
  static bool set_here = false;
  if (users_own) return false;
  if (!serial && !set_here) return true;   // unset: lavapipe's default
  // setenv once the variable exists swaps its string, leaving environ's array as it is.
  const unsigned cores = std::thread::hardware_concurrency();   // lavapipe's default (0 on one core)
  const std::string threads = serial ? "0" : std::to_string(cores > 1 ? cores : 0);
  setenv("LP_NUM_THREADS", threads.c_str(), 1);
  set_here = true;
  return true;
}

// An instance (no surface extensions: compute only), with the validation layer and its
// messenger when asked for and installed. Null instance with `why` set when there is none.
VulkanInstance create_vulkan_instance(std::string& why, bool with_validation) {
  VulkanInstance result;
  result.api = open_loader(why);
  if (!result.api) return result;
  VulkanApi& api = *result.api;
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "sigmafem";
  // Vulkan 1.1 where the loader has it: SPIR-V 1.3's subgroup operations (factor_solve_split)
  // on the devices that have 1.1 too; a 1.0 loader would refuse the instance.
  std::uint32_t loader_version = VK_API_VERSION_1_0;
  if (api.vkEnumerateInstanceVersion && api.vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS)
    loader_version = VK_API_VERSION_1_0;
  app.apiVersion = loader_version >= VK_API_VERSION_1_1 ? VK_API_VERSION_1_1 : VK_API_VERSION_1_0;
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
  if (app.apiVersion < VK_API_VERSION_1_1) api.vkGetPhysicalDeviceProperties2 = nullptr;   // not ours to call
  if (validation && api.vkCreateDebugUtilsMessengerEXT) {
    messenger.pNext = nullptr;
    if (api.vkCreateDebugUtilsMessengerEXT(result.instance, &messenger, nullptr,
                                           &result.messenger) != VK_SUCCESS)
      result.messenger = VK_NULL_HANDLE;
  }
  return result;
}

void destroy_vulkan_instance(VulkanInstance& instance) {
  if (!instance.instance) return;
  if (instance.messenger) instance.api->vkDestroyDebugUtilsMessengerEXT(instance.instance, instance.messenger, nullptr);
  instance.api->vkDestroyInstance(instance.instance, nullptr);
  instance.instance = VK_NULL_HANDLE;
}

std::vector<VkPhysicalDevice> vulkan_physical_devices(const VulkanInstance& instance) {
  std::uint32_t count = 0;
  if (instance.api->vkEnumeratePhysicalDevices(instance.instance, &count, nullptr) != VK_SUCCESS)
    return {};
  std::vector<VkPhysicalDevice> devices(count);
  if (instance.api->vkEnumeratePhysicalDevices(instance.instance, &count, devices.data()) != VK_SUCCESS)
    return {};
  devices.resize(count);
  return devices;
}

VulkanDeviceInfo describe_vulkan_device(const VulkanApi& api, VkPhysicalDevice device, int index) {
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
  info.max_texel_elements = properties.limits.maxTexelBufferElements;
  if (api.vkGetPhysicalDeviceProperties2 && properties.apiVersion >= VK_API_VERSION_1_1) {
    VkPhysicalDeviceSubgroupProperties subgroup{};
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    VkPhysicalDeviceProperties2 properties2{};
    properties2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties2.pNext = &subgroup;
    api.vkGetPhysicalDeviceProperties2(device, &properties2);
    info.subgroup_size = subgroup.subgroupSize;
    info.subgroup_shuffle = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0 &&
                            (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_BIT) != 0;
  }
  return info;
}

const char* const kNoVulkanDevice =
    "no Vulkan device found: install a driver (on Debian, lavapipe for the CPU: apt-get "
    "install mesa-vulkan-drivers) or use another --backend";


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
  VulkanInstance instance = create_vulkan_instance(why, false);
  std::vector<VulkanDeviceInfo> list;
  if (instance.instance) {
    const std::vector<VkPhysicalDevice> devices = vulkan_physical_devices(instance);
    for (std::size_t i = 0; i < devices.size(); ++i)
      list.push_back(describe_vulkan_device(*instance.api, devices[i], static_cast<int>(i)));
    if (list.empty()) why = kNoVulkanDevice;
    destroy_vulkan_instance(instance);
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

}  // namespace sigmafem
