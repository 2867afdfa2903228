#include "host/vulkan/vulkan_device.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "host/ensemble/device_readout.h"
#include "host/vulkan/vulkan_instance.h"
#include "host/vulkan/vulkan_shaders.h"

namespace sigmafem {

VulkanDevice::VulkanDevice(int index, Precision precision, bool lavapipe_serial) : precision_(precision) {
  std::string why;
  choose_lavapipe_threads(lavapipe_serial);
  VulkanInstance instance = create_vulkan_instance(why, true);
  if (!instance.instance) throw DeviceError(why);
  api_ = instance.api;
  instance_ = instance.instance;
  messenger_ = instance.messenger;
  // The destructor does not run when the constructor throws: release() by hand then.
  try {
    const std::vector<VkPhysicalDevice> devices = vulkan_physical_devices(instance);
    if (devices.empty()) throw DeviceError(kNoVulkanDevice);
    if (index < 0 || index >= static_cast<int>(devices.size()))
      throw DeviceError("no Vulkan device " + std::to_string(index) + ": there are " +
                        std::to_string(devices.size()) + " (see `sigmafem devices`)");
    physical_ = devices[index];
    info_ = describe_vulkan_device(*api_, physical_, index);
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
    const bool profile = std::getenv("SIGMAFEM_VULKAN_PROFILE") != nullptr &&
                         families[queue_family_].timestampValidBits > 0;
    timestamp_seconds_ = 1e-9 * static_cast<double>(properties.limits.timestampPeriod);

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
    // 240 buffers in all, of any kind; one storage texel buffer, the factor's work vector).
    const VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1024},
                                           {VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, 1024},
                                           {VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER, 256}};
    VkDescriptorPoolCreateInfo descriptors{};
    descriptors.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    descriptors.maxSets = 64;
    descriptors.poolSizeCount = 3;
    descriptors.pPoolSizes = sizes;
    check(api_->vkCreateDescriptorPool(device_, &descriptors, nullptr, &descriptor_pool_),
          "creating a descriptor pool");

    if (profile) {
      VkQueryPoolCreateInfo queries{};
      queries.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
      queries.queryType = VK_QUERY_TYPE_TIMESTAMP;
      queries.queryCount = 2 * kProfiledDispatches;
      check(api_->vkCreateQueryPool(device_, &queries, nullptr, &profile_queries_),
            "creating the profile's timestamp queries");
    }

    reserve_read_back(4096);
  } catch (...) {
    release();
    throw;
  }
}

VulkanDevice::~VulkanDevice() {
  print_profile();
  release();
}

void VulkanDevice::release() {
  if (device_) {
    api_->vkDeviceWaitIdle(device_);
    if (profile_queries_) api_->vkDestroyQueryPool(device_, profile_queries_, nullptr);
    for (const VulkanKernel& k : kernels_) {
      api_->vkDestroyPipeline(device_, k.pipeline, nullptr);
      api_->vkDestroyPipelineLayout(device_, k.layout, nullptr);
      api_->vkDestroyDescriptorSetLayout(device_, k.set_layout, nullptr);
    }
    kernels_.clear();
    for (const TexelView& v : views_) api_->vkDestroyBufferView(device_, v.view, nullptr);
    views_.clear();
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
  // Whole 8-byte texels, so that a float64 shader's texel view (R32G32_UINT) covers it all.
  bytes = std::max<std::size_t>(8, (bytes + 7) / 8 * 8);
  if (bytes > info_.max_buffer)
    throw DeviceError(std::string("out of device memory: ") + what + " needs " +
                      std::to_string(bytes >> 20) + " MiB in one buffer; " + info_.name +
                      " allows " + std::to_string(info_.max_buffer >> 20) +
                      " MiB (maxStorageBufferRange). Use fewer sigma points or a coarser mesh");
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = bytes;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT |
               VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
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

VulkanKernel VulkanDevice::kernel(const char* name, int bindings, const std::vector<std::uint32_t>& constants) {
  const bool want_double = precision_ == Precision::double_precision;
  const EmbeddedShader* found = nullptr;
  for (std::size_t i = 0; i < kVulkanShaderCount; ++i) {
    const EmbeddedShader& shader = kVulkanShaders[i];
    if (shader.double_precision != want_double || std::strcmp(shader.name, name) != 0) continue;
    if (found == nullptr || shader.texel_reads == texel_reads_) found = &shader;
  }
  if (found != nullptr)
    return kernel_from_spirv(name, found->words, found->word_count, bindings, constants);
  throw DeviceError(std::string("no embedded Vulkan shader '") + name + "' (" +
                    (want_double ? "double" : "single") +
                    " precision): the build did not compile it from kernels/vulkan/");
}

VulkanKernel VulkanDevice::kernel_from_spirv(const std::string& name, const std::uint32_t* words,
                                             std::size_t word_count, int bindings,
                                             const std::vector<std::uint32_t>& constants) {
  // Drivers may crash on a module that is not SPIR-V, so look at its header first.
  constexpr std::uint32_t kSpirvMagic = 0x07230203;
  if (word_count < 5 || words == nullptr || words[0] != kSpirvMagic)
    throw DeviceError("the Vulkan shader " + name + " failed to load on " + info_.name +
                      ": not a SPIR-V module (bad header); rebuild sigmafem");
  VulkanKernel k;
  k.name = name;
  // Each binding as the shader declares it; one the shader does not use stays a storage buffer.
  k.kinds.assign(static_cast<std::size_t>(bindings), SpirvBinding::storage_buffer);
  try {
    for (const auto& [binding, kind] : spirv_bindings(words, word_count))
      if (binding < k.kinds.size()) k.kinds[binding] = kind;
  } catch (const std::invalid_argument& e) {
    throw DeviceError("the Vulkan shader " + name + " failed to load on " + info_.name + ": " +
                      e.what() + "; rebuild sigmafem");
  }
  VkShaderModule module = VK_NULL_HANDLE;
  try {
    std::vector<VkDescriptorSetLayoutBinding> slots(bindings);
    for (int b = 0; b < bindings; ++b) {
      slots[b] = {};
      slots[b].binding = static_cast<std::uint32_t>(b);
      slots[b].descriptorType = k.kinds[b] == SpirvBinding::storage_buffer
                                    ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER
                                : storage_texels(k.kinds[b])
                                    ? VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER
                                    : VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
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
    std::vector<VkSpecializationMapEntry> entries;
    for (std::uint32_t i = 0; i < constants.size(); ++i)
      entries.push_back({i, i * static_cast<std::uint32_t>(sizeof(std::uint32_t)), sizeof(std::uint32_t)});
    const VkSpecializationInfo specialization{static_cast<std::uint32_t>(entries.size()), entries.data(),
                                              constants.size() * sizeof(std::uint32_t), constants.data()};
    VkComputePipelineCreateInfo pipeline{};
    pipeline.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    pipeline.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    pipeline.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    pipeline.stage.module = module;
    pipeline.stage.pName = "main";
    pipeline.stage.pSpecializationInfo = constants.empty() ? nullptr : &specialization;
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
  if (buffers.size() != kernel.kinds.size())
    throw std::logic_error("VulkanDevice::bind: " + kernel.name + " takes " +
                           std::to_string(kernel.kinds.size()) + " buffers, given " +
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
  std::vector<VkBufferView> views(buffers.size(), VK_NULL_HANDLE);
  std::vector<VkWriteDescriptorSet> writes(buffers.size());
  for (std::size_t b = 0; b < buffers.size(); ++b) {
    writes[b] = {};
    writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[b].dstSet = set;
    writes[b].dstBinding = static_cast<std::uint32_t>(b);
    writes[b].descriptorCount = 1;
    if (kernel.kinds[b] == SpirvBinding::storage_buffer) {
      infos[b] = {buffers[b].buffer, 0, VK_WHOLE_SIZE};
      writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      writes[b].pBufferInfo = &infos[b];
    } else {
      views[b] = texel_view(buffers[b], kernel.kinds[b], kernel.name);
      writes[b].descriptorType = storage_texels(kernel.kinds[b])
                                     ? VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER
                                     : VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER;
      writes[b].pTexelBufferView = &views[b];
    }
  }
  api_->vkUpdateDescriptorSets(device_, static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
  return set;
}

VkBufferView VulkanDevice::texel_view(const VulkanBuffer& buffer, SpirvBinding kind,
                                      const std::string& kernel) {
  // A float64 shader's unsigned texels are its doubles (kernels/vulkan/ensemble_layout.h).
  const bool doubles = kind == SpirvBinding::uint_texels && precision_ == Precision::double_precision;
  const VkFormat format = kind == SpirvBinding::float_texels || kind == SpirvBinding::float_image
                              ? VK_FORMAT_R32_SFLOAT
                          : kind == SpirvBinding::float4_image || kind == SpirvBinding::float4_texels
                              ? VK_FORMAT_R32G32B32A32_SFLOAT
                          : kind == SpirvBinding::int_texels ? VK_FORMAT_R32_SINT
                          : doubles                          ? VK_FORMAT_R32G32_UINT
                                                             : VK_FORMAT_R32_UINT;
  for (const TexelView& v : views_)
    if (v.buffer == buffer.buffer && v.format == format) return v.view;
  const bool four = kind == SpirvBinding::float4_image || kind == SpirvBinding::float4_texels;
  const std::size_t texels = buffer.bytes / (doubles ? 8 : four ? 16 : 4);
  if (texels > info_.max_texel_elements)
    throw DeviceError("the Vulkan shader " + kernel + " reads a buffer of " +
                      std::to_string(texels) + " texels; " + info_.name +
                      " allows " + std::to_string(info_.max_texel_elements) +
                      " (maxTexelBufferElements); use fewer sigma points");
  VkBufferViewCreateInfo create{};
  create.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO;
  create.buffer = buffer.buffer;
  create.format = format;
  create.offset = 0;
  create.range = VK_WHOLE_SIZE;
  VkBufferView view = VK_NULL_HANDLE;
  check(api_->vkCreateBufferView(device_, &create, nullptr, &view), "creating a texel view for " + kernel);
  views_.push_back({buffer.buffer, format, view});
  return view;
}

VkCommandBuffer VulkanDevice::begin() {
  check(api_->vkResetCommandBuffer(command_buffer_, 0), "resetting the command buffer");
  VkCommandBufferBeginInfo begin_info{};
  begin_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin_info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(api_->vkBeginCommandBuffer(command_buffer_, &begin_info), "recording a command buffer");
  if (profile_queries_) {
    api_->vkCmdResetQueryPool(command_buffer_, profile_queries_, 0, 2 * kProfiledDispatches);
    profiled_.clear();
  }
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
  const bool timed = profile_queries_ && profiled_.size() < kProfiledDispatches;
  const std::uint32_t query = 2 * static_cast<std::uint32_t>(profiled_.size());
  if (timed) api_->vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, profile_queries_, query);
  api_->vkCmdDispatch(cmd, x, y, 1);
  if (timed) {
    api_->vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, profile_queries_, query + 1);
    profiled_.push_back(kernel.name);
  }
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
  collect_profile();
}

void VulkanDevice::collect_profile() {
  if (!profile_queries_ || profiled_.empty()) return;
  std::vector<std::uint64_t> ticks(2 * profiled_.size());
  check(api_->vkGetQueryPoolResults(device_, profile_queries_, 0,
                                    static_cast<std::uint32_t>(ticks.size()),
                                    ticks.size() * sizeof(std::uint64_t), ticks.data(),
                                    sizeof(std::uint64_t),
                                    VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "reading the profile's timestamps");
  // A GPU may take a start timestamp before the last dispatch's end: such spans count as 0.
  auto span = [&](std::uint64_t from, std::uint64_t to) {
    return to > from ? timestamp_seconds_ * static_cast<double>(to - from) : 0.0;
  };
  for (std::size_t i = 0; i < profiled_.size(); ++i) {
    KernelTime& time = profile_[profiled_[i]];
    time.seconds += span(ticks[2 * i], ticks[2 * i + 1]);
    ++time.dispatches;
    if (i > 0) profile_between_ += span(ticks[2 * i - 1], ticks[2 * i]);
  }
  profiled_.clear();
}

void VulkanDevice::print_profile() const {
  if (profile_.empty()) return;
  std::cerr << "Vulkan shader times on " << info_.name << " (SIGMAFEM_VULKAN_PROFILE):\n";
  for (const auto& [name, time] : profile_)
    std::cerr << "  " << name << ": " << time.dispatches << " dispatches, " << time.seconds
              << " s, " << 1e6 * time.seconds / static_cast<double>(time.dispatches)
              << " us each\n";
  std::cerr << "  between dispatches (barriers, copies, updates): " << profile_between_ << " s\n";
}

void VulkanDevice::upload_reals(const VulkanBuffer& buffer, const std::vector<double>& values) {
  const std::vector<unsigned char> bytes = to_device_reals(values, precision_);
  if (!bytes.empty()) upload(buffer, bytes.data(), bytes.size());
}

void VulkanDevice::update_reals(VkCommandBuffer cmd, const VulkanBuffer& buffer, const std::vector<double>& values) {
  const std::vector<unsigned char> bytes = to_device_reals(values, precision_);
  update(cmd, buffer, bytes.data(), bytes.size());
}

}  // namespace sigmafem
