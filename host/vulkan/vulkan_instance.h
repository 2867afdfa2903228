// The process-wide side of Vulkan: the loader (libvulkan.so.1, opened at run time, so that a
// machine without it still runs the other back ends), instances with the validation layer
// when asked for, and device discovery. VulkanDevice (vulkan_device.h) builds one device on it.
#pragma once

#include <vulkan/vulkan.h>

#include <memory>
#include <string>
#include <vector>

#include "host/vulkan/vulkan_device.h"

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
  X(vkCreateBufferView)                      \
  X(vkDestroyBufferView)                     \
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
  X(vkDeviceWaitIdle)                        \
  X(vkCreateQueryPool)                       \
  X(vkDestroyQueryPool)                      \
  X(vkCmdResetQueryPool)                     \
  X(vkCmdWriteTimestamp)                     \
  X(vkGetQueryPoolResults)

struct VulkanApi {
  void* library = nullptr;
  PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
#define SF_DECLARE(name) PFN_##name name = nullptr;
  SF_VULKAN_GLOBAL_FUNCTIONS(SF_DECLARE)
  SF_VULKAN_INSTANCE_FUNCTIONS(SF_DECLARE)
#undef SF_DECLARE
  PFN_vkCreateDebugUtilsMessengerEXT vkCreateDebugUtilsMessengerEXT = nullptr;
  PFN_vkDestroyDebugUtilsMessengerEXT vkDestroyDebugUtilsMessengerEXT = nullptr;
  // Vulkan 1.1's, null on a 1.0 loader or instance: the loader's version, and the subgroup
  // properties (factor_solve's split block rows, host/vulkan/vulkan_factor_solve.h).
  PFN_vkEnumerateInstanceVersion vkEnumerateInstanceVersion = nullptr;
  PFN_vkGetPhysicalDeviceProperties2 vkGetPhysicalDeviceProperties2 = nullptr;

  // Loads the instance-level functions (device functions too, through the loader's
  // trampolines) for `instance`.
  void load(VkInstance instance) {
#define SF_LOAD_FUNCTION(name) name = reinterpret_cast<PFN_##name>(vkGetInstanceProcAddr(instance, #name));
    SF_VULKAN_INSTANCE_FUNCTIONS(SF_LOAD_FUNCTION)
#undef SF_LOAD_FUNCTION
    vkCreateDebugUtilsMessengerEXT = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    vkDestroyDebugUtilsMessengerEXT = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    vkGetPhysicalDeviceProperties2 = reinterpret_cast<PFN_vkGetPhysicalDeviceProperties2>(
        vkGetInstanceProcAddr(instance, "vkGetPhysicalDeviceProperties2"));
  }
};

struct VulkanInstance {
  std::shared_ptr<VulkanApi> api;
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
};

// An instance (no surface extensions: compute only), with the validation layer and its
// messenger when asked for (SIGMAFEM_VULKAN_VALIDATION=1) and installed. A null instance with
// `why` set when there is none.
VulkanInstance create_vulkan_instance(std::string& why, bool with_validation);
void destroy_vulkan_instance(VulkanInstance& instance);
std::vector<VkPhysicalDevice> vulkan_physical_devices(const VulkanInstance& instance);
VulkanDeviceInfo describe_vulkan_device(const VulkanApi& api, VkPhysicalDevice device, int index);
// The message when there is no device.
extern const char* const kNoVulkanDevice;

}  // namespace sigmafem
