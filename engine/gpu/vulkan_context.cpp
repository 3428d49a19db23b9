#include "engine/gpu/vulkan_context.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_error.h"

namespace engine::gpu {
namespace {

DeviceKind kind_of(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return DeviceKind::Discrete;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return DeviceKind::Integrated;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return DeviceKind::Virtual;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return DeviceKind::Cpu;
    default: return DeviceKind::Other;
  }
}

// The first queue family with compute that `accepts` (if set) accepts too.
std::optional<std::uint32_t> compute_family(VkInstance instance, VkPhysicalDevice d,
                                            const std::function<bool(VkInstance, VkPhysicalDevice, std::uint32_t)>& accepts) {
  std::uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(d, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(d, &n, families.data());
  for (std::uint32_t i = 0; i < n; ++i)
    if ((families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && (!accepts || accepts(instance, d, i))) return i;
  return std::nullopt;
}

bool has_extensions(VkPhysicalDevice d, std::initializer_list<const char*> names) {
  std::uint32_t n = 0;
  if (vkEnumerateDeviceExtensionProperties(d, nullptr, &n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> all(n);
  vkEnumerateDeviceExtensionProperties(d, nullptr, &n, all.data());
  for (const char* name : names)
    if (std::none_of(all.begin(), all.end(), [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; }))
      return false;
  return true;
}

bool layer_installed(const char* name) {
  std::uint32_t n = 0;
  if (vkEnumerateInstanceLayerProperties(&n, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  for (const auto& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return true;
  return false;
}


}  // namespace

// What a physical device can do, of what the kernels use.
struct DeviceFeatures {
  bool ray_query = false;  // the three extensions, rayQuery, accelerationStructure, bufferDeviceAddress
  bool float16 = false;
  bool int64 = false;
  std::string driver;
  std::uint32_t scratch_alignment = 0;
};

static DeviceFeatures query_features(VkPhysicalDevice physical) {
  // Ray queries need three extensions and three features; the feature
  // structs are chained only where the extensions exist, as the spec asks.
  const bool has_ray_query_extensions =
      has_extensions(physical, {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                                VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME});
  VkPhysicalDeviceRayQueryFeaturesKHR frq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR fas{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  fas.pNext = &frq;
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  if (has_ray_query_extensions) f12.pNext = &fas;
  VkPhysicalDeviceFeatures2 f2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  f2.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(physical, &f2);
  VkPhysicalDeviceAccelerationStructurePropertiesKHR pas{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
  VkPhysicalDeviceVulkan12Properties p12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
  if (has_ray_query_extensions) p12.pNext = &pas;
  VkPhysicalDeviceProperties2 p2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  p2.pNext = &p12;
  vkGetPhysicalDeviceProperties2(physical, &p2);
  DeviceFeatures f;
  f.ray_query = has_ray_query_extensions && frq.rayQuery && fas.accelerationStructure && f12.bufferDeviceAddress;
  f.float16 = f12.shaderFloat16 == VK_TRUE;
  f.int64 = f2.features.shaderInt64 == VK_TRUE;
  f.driver = std::string(p12.driverName) + " " + p12.driverInfo;
  f.scratch_alignment = pas.minAccelerationStructureScratchOffsetAlignment;
  return f;
}

std::string VulkanContext::describe_device(const GpuOptions& options, const DeviceFeatures& features, bool ray_query_enabled) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physical_, &props);
  bool want_ray_query = options.ray_query;
  if (const char* env = std::getenv("ENGINE_GPU_RAY_QUERY")) {
    if (std::strcmp(env, "off") == 0) want_ray_query = false;
    else if (std::strcmp(env, "on") != 0) return std::string("ENGINE_GPU_RAY_QUERY=") + env + ": expected on or off";
  }
  info_.ray_query = want_ray_query && ray_query_enabled;
  bool want_raster = options.raster_visibility;
  if (const char* env = std::getenv("ENGINE_GPU_RASTER_VISIBILITY")) {
    if (std::strcmp(env, "off") == 0) want_raster = false;
    else if (std::strcmp(env, "on") == 0) want_raster = true;
    else return std::string("ENGINE_GPU_RASTER_VISIBILITY=") + env + ": expected on or off";
  }
  std::uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
  std::vector<VkQueueFamilyProperties> family(families);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, family.data());
  info_.graphics_queue = queue_family_ < families && (family[queue_family_].queueFlags & VK_QUEUE_GRAPHICS_BIT);
  info_.raster_visibility = want_raster && info_.graphics_queue;
  info_.scratch_alignment = features.scratch_alignment;
  info_.name = props.deviceName;
  info_.kind = kind_of(props.deviceType);
  info_.driver = features.driver;
  info_.shader_float16 = features.float16;
  info_.shader_int64 = features.int64;
  info_.max_shared_memory = props.limits.maxComputeSharedMemorySize;
  info_.max_storage_buffer_range = props.limits.maxStorageBufferRange;
  if (options.storage_buffer_range_cap > 0) info_.max_storage_buffer_range = std::min(info_.max_storage_buffer_range, options.storage_buffer_range_cap);
  info_.buffer_memory = options.buffer_memory;
  info_.stage_device_only = options.stage_device_only;
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mem);
  for (std::uint32_t i = 0; i < mem.memoryTypeCount; ++i) {
    const VkMemoryPropertyFlags f = mem.memoryTypes[i].propertyFlags;
    constexpr VkMemoryPropertyFlags kWanted =
        VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    if ((f & kWanted) == kWanted)
      info_.mappable_device_local_bytes = std::max<std::uint64_t>(info_.mappable_device_local_bytes, mem.memoryHeaps[mem.memoryTypes[i].heapIndex].size);
  }
  if (const char* env = std::getenv("ENGINE_GPU_MEMORY")) {
    if (std::strcmp(env, "cached") == 0) info_.buffer_memory = BufferMemory::Cached;
    else if (std::strcmp(env, "write-combined") == 0) info_.buffer_memory = BufferMemory::WriteCombined;
    else if (std::strcmp(env, "bar") == 0) info_.buffer_memory = BufferMemory::Bar;
    else return std::string("ENGINE_GPU_MEMORY=") + env + ": expected cached, write-combined or bar";
  }
  return {};
}

std::string VulkanContext::make_submission_objects(const VkPhysicalDeviceProperties& props) {
  if (info_.ray_query) {
    auto& api = as_api_;
    const VkDevice dev = device_;
    api.create = reinterpret_cast<PFN_vkCreateAccelerationStructureKHR>(vkGetDeviceProcAddr(dev, "vkCreateAccelerationStructureKHR"));
    api.destroy = reinterpret_cast<PFN_vkDestroyAccelerationStructureKHR>(vkGetDeviceProcAddr(dev, "vkDestroyAccelerationStructureKHR"));
    api.build_sizes = reinterpret_cast<PFN_vkGetAccelerationStructureBuildSizesKHR>(
        vkGetDeviceProcAddr(dev, "vkGetAccelerationStructureBuildSizesKHR"));
    api.cmd_build = reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresKHR>(
        vkGetDeviceProcAddr(dev, "vkCmdBuildAccelerationStructuresKHR"));
    api.device_address = reinterpret_cast<PFN_vkGetAccelerationStructureDeviceAddressKHR>(
        vkGetDeviceProcAddr(dev, "vkGetAccelerationStructureDeviceAddressKHR"));
    if (!api.create || !api.destroy || !api.build_sizes || !api.cmd_build || !api.device_address)
      return "the device lists VK_KHR_acceleration_structure but its entry points are missing";
  }

  VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = queue_family_;
  ENGINE_VK_CHECK(vkCreateCommandPool(device_, &pci, nullptr, &pool_));
  VkCommandBufferAllocateInfo cai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool_;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  ENGINE_VK_CHECK(vkAllocateCommandBuffers(device_, &cai, &cmd_));
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  ENGINE_VK_CHECK(vkCreateFence(device_, &fci, nullptr, &fence_));

  std::uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
  std::vector<VkQueueFamilyProperties> fam(families);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, fam.data());
  if (fam[queue_family_].timestampValidBits > 0 && props.limits.timestampPeriod > 0) {
    VkQueryPoolCreateInfo qpi{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qpi.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qpi.queryCount = kMaxStageMarks + 2;  // the start, the stage marks, the end
    ENGINE_VK_CHECK(vkCreateQueryPool(device_, &qpi, nullptr, &timestamps_));
    info_.timestamp_period_ns = props.limits.timestampPeriod;
  }
  return {};
}

VKAPI_ATTR VkBool32 VKAPI_CALL VulkanContext::on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                            VkDebugUtilsMessageTypeFlagsEXT,
                                                            const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                            void* self) {
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    ++static_cast<VulkanContext*>(self)->validation_errors_;
    std::fprintf(stderr, "vulkan validation error: %s\n", data->pMessage);
  } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    std::fprintf(stderr, "vulkan validation warning: %s\n", data->pMessage);
  }
  return VK_FALSE;
}

std::unique_ptr<VulkanContext> VulkanContext::create(const GpuOptions& options, std::string* why_not) {
  auto fail = [&](std::string why) {
    if (why_not) *why_not = std::move(why);
    return std::unique_ptr<VulkanContext>();
  };
  std::unique_ptr<VulkanContext> ctx(new VulkanContext());

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "engine";
  app.apiVersion = VK_API_VERSION_1_2;
  std::vector<const char*> layers, extensions;
  const char* kValidation = "VK_LAYER_KHRONOS_validation";
  const bool validate = options.validation && layer_installed(kValidation);
  if (validate) {
    layers.push_back(kValidation);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  extensions.insert(extensions.end(), options.instance_extensions.begin(), options.instance_extensions.end());
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  if (const VkResult r = vkCreateInstance(&ici, nullptr, &ctx->instance_); r != VK_SUCCESS)
    return fail("vkCreateInstance failed: " + vk_result_name(r) + " (is a Vulkan driver installed? Debian: mesa-vulkan-drivers)");

  if (validate) {
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(ctx->instance_, "vkCreateDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    mci.pfnUserCallback = &VulkanContext::on_validation;
    mci.pUserData = ctx.get();
    if (create_messenger) ENGINE_VK_CHECK(create_messenger(ctx->instance_, &mci, nullptr, &ctx->messenger_));
  }

  std::uint32_t count = 0;
  ENGINE_VK_CHECK(vkEnumeratePhysicalDevices(ctx->instance_, &count, nullptr));
  std::vector<VkPhysicalDevice> physicals(count);
  ENGINE_VK_CHECK(vkEnumeratePhysicalDevices(ctx->instance_, &count, physicals.data()));
  std::vector<DeviceCandidate> candidates;
  for (auto p : physicals) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(p, &props);
    candidates.push_back({props.deviceName, kind_of(props.deviceType),
                          compute_family(ctx->instance_, p, options.queue_family_accepts).has_value()});
  }
  std::string requested = options.device;
  if (requested.empty())
    if (const char* env = std::getenv("ENGINE_GPU_DEVICE")) requested = env;
  const DeviceChoice choice = choose_device(candidates, requested);
  if (!choice.index) return fail(choice.why);
  ctx->physical_ = physicals[*choice.index];
  ctx->queue_family_ = *compute_family(ctx->instance_, ctx->physical_, options.queue_family_accepts);

  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(ctx->physical_, &props);
  const DeviceFeatures features = query_features(ctx->physical_);
  if (std::string why = ctx->describe_device(options, features, features.ray_query); !why.empty()) return fail(why);

  // Enable only what the kernels use, so a device without float16 still runs
  // the fp32 variants.
  VkPhysicalDeviceVulkan12Features enable12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  enable12.shaderFloat16 = features.float16 ? VK_TRUE : VK_FALSE;
  // 64-bit integers: the shading kernels draw Pcg32's numbers bit for bit.
  VkPhysicalDeviceFeatures2 enable2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  enable2.features.shaderInt64 = features.int64 ? VK_TRUE : VK_FALSE;
  enable2.pNext = &enable12;
  VkPhysicalDeviceRayQueryFeaturesKHR enable_rq{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR enable_as{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  std::vector<const char*> device_extensions;
  if (ctx->info_.ray_query) {
    enable12.bufferDeviceAddress = VK_TRUE;
    enable_as.accelerationStructure = VK_TRUE;
    enable_rq.rayQuery = VK_TRUE;
    enable_as.pNext = &enable_rq;
    enable12.pNext = &enable_as;
    device_extensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME, VK_KHR_RAY_QUERY_EXTENSION_NAME,
                         VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};
  }
  device_extensions.insert(device_extensions.end(), options.device_extensions.begin(), options.device_extensions.end());
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = ctx->queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = &enable2;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = static_cast<std::uint32_t>(device_extensions.size());
  dci.ppEnabledExtensionNames = device_extensions.data();
  ENGINE_VK_CHECK(vkCreateDevice(ctx->physical_, &dci, nullptr, &ctx->device_));
  vkGetDeviceQueue(ctx->device_, ctx->queue_family_, 0, &ctx->queue_);
  if (std::string why = ctx->make_submission_objects(props); !why.empty()) return fail(why);
  return ctx;
}

std::unique_ptr<VulkanContext> VulkanContext::adopt(const HostVulkanDevice& host, const GpuOptions& options, std::string* why_not) {
  auto fail = [&](std::string why) {
    if (why_not) *why_not = std::move(why);
    return std::unique_ptr<VulkanContext>();
  };
  if (!host.instance || !host.physical_device || !host.device || !host.queue)
    return fail("the host's Vulkan device is incomplete: instance, physical device, device and queue are all needed");
  std::uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(host.physical_device, &families, nullptr);
  std::vector<VkQueueFamilyProperties> fam(families);
  vkGetPhysicalDeviceQueueFamilyProperties(host.physical_device, &families, fam.data());
  if (host.queue_family >= families || !(fam[host.queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT))
    return fail("the host's queue family " + std::to_string(host.queue_family) + " has no compute");
  std::unique_ptr<VulkanContext> ctx(new VulkanContext());
  ctx->owns_device_ = false;
  ctx->instance_ = host.instance;
  ctx->physical_ = host.physical_device;
  ctx->device_ = host.device;
  ctx->queue_ = host.queue;
  ctx->queue_family_ = host.queue_family;
  // What the device supports, narrowed to what the host says it enabled.
  DeviceFeatures features = query_features(host.physical_device);
  features.float16 = features.float16 && host.enabled_shader_float16;
  features.int64 = features.int64 && host.enabled_shader_int64;
  if (std::string why = ctx->describe_device(options, features, features.ray_query && host.enabled_ray_query); !why.empty())
    return fail(why);
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(ctx->physical_, &props);
  if (std::string why = ctx->make_submission_objects(props); !why.empty()) return fail(why);
  return ctx;
}

VulkanContext::~VulkanContext() {
  if (device_) {
    // A host's device keeps running the host's work: wait for our queue
    // only (every submission of ours has already been waited for).
    if (owns_device_)
      vkDeviceWaitIdle(device_);
    else if (queue_)
      vkQueueWaitIdle(queue_);
    if (timestamps_) vkDestroyQueryPool(device_, timestamps_, nullptr);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    if (owns_device_) vkDestroyDevice(device_, nullptr);
  }
  if (!owns_device_) return;  // the host's instance, and no messenger of ours
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

std::uint32_t VulkanContext::memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags flags) const {
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mem);
  for (std::uint32_t i = 0; i < mem.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (mem.memoryTypes[i].propertyFlags & flags) == flags) return i;
  throw GpuError("no Vulkan memory type with flags " + std::to_string(flags) + " on " + info_.name);
}

std::string describe(const DeviceInfo& info) {
  const char* buffers = info.buffer_memory == BufferMemory::Cached          ? "cached host"
                        : info.buffer_memory == BufferMemory::WriteCombined ? "write-combined host"
                                                                            : "BAR device-local";
  char bar[64] = "none";
  if (info.mappable_device_local_bytes > 0)
    std::snprintf(bar, sizeof bar, "%.1f GiB", static_cast<double>(info.mappable_device_local_bytes) / (1u << 30));
  return "vulkan (" + info.name + "; " + info.driver + "; mapped buffers: " + buffers + "; mappable device-local heap: " +
         bar + "; rays: " + (info.ray_query ? "VK_KHR_ray_query" : "compute BVH traversal") +
         "; camera: " + (info.raster_visibility ? "raster visibility pass" : "rays") + ")";
}

std::vector<std::uint32_t> rank_buffer_memory_types(const VkPhysicalDeviceMemoryProperties& mem, std::uint32_t type_bits,
                                                    bool mapped, BufferMemory preference) {
  constexpr VkMemoryPropertyFlags kMappable = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  // Lower rank = better; -1 = unusable.
  auto rank = [&](VkMemoryPropertyFlags f) -> int {
    const bool mappable = (f & kMappable) == kMappable;
    const bool local = f & VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    const bool cached = f & VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
    if (!mapped) return local ? (mappable ? 1 : 0) : 2;
    if (!mappable) return -1;
    switch (preference) {
      case BufferMemory::Cached: return (cached ? 0 : 2) + (local ? 1 : 0);
      case BufferMemory::WriteCombined: return (cached ? 2 : 0) + (local ? 1 : 0);
      case BufferMemory::Bar: return (local ? 0 : 2) + (cached ? 1 : 0);
    }
    return -1;
  };
  std::vector<std::pair<int, std::uint32_t>> ranked;
  for (std::uint32_t i = 0; i < mem.memoryTypeCount; ++i)
    if (type_bits & (1u << i))
      if (const int r = rank(mem.memoryTypes[i].propertyFlags); r >= 0) ranked.emplace_back(r, i);
  std::stable_sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<std::uint32_t> out;
  for (const auto& [r, i] : ranked) out.push_back(i);
  return out;
}

std::vector<std::uint32_t> VulkanContext::buffer_memory_types(std::uint32_t type_bits, bool mapped) const {
  VkPhysicalDeviceMemoryProperties mem;
  vkGetPhysicalDeviceMemoryProperties(physical_, &mem);
  return rank_buffer_memory_types(mem, type_bits, mapped, info_.buffer_memory);
}

std::uint32_t VulkanContext::record_deferred(VkCommandBuffer cmd, std::vector<const void*>& owners) {
  owners.clear();
  if (deferred_.empty()) return 0;
  // Taken first: a recording may queue nothing more, but must not see itself.
  std::vector<Deferred> queued = std::move(deferred_);
  deferred_.clear();
  for (Deferred& d : queued) {
    d.record(cmd);
    owners.push_back(d.owner);
    mark_stage(cmd);
  }
  // Whatever they wrote is ready for the submission's own commands.
  record_memory_barrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                        VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
  return marks_;
}

void VulkanContext::record_before_next(const void* owner, std::function<void(VkCommandBuffer)> record) {
  deferred_.push_back({owner, std::move(record)});
}

void VulkanContext::flush() {
  if (!deferred_.empty()) submit_and_wait([](VkCommandBuffer) {});
}

bool VulkanContext::has_deferred(const void* owner) const {
  for (const Deferred& d : deferred_)
    if (d.owner == owner) return true;
  return false;
}

void VulkanContext::forget_deferred(const void* owner) {
  std::erase_if(deferred_, [&](const Deferred& d) { return d.owner == owner; });
  std::erase_if(deferred_ms_, [&](const std::pair<const void*, double>& t) { return t.first == owner; });
}

double VulkanContext::take_deferred_ms(const void* owner) {
  double ms = 0.0;
  for (auto& [who, t] : deferred_ms_)
    if (who == owner) ms += std::exchange(t, 0.0);
  return ms;
}

double VulkanContext::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) {
  ENGINE_VK_CHECK(vkResetCommandBuffer(cmd_, 0));
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  ENGINE_VK_CHECK(vkBeginCommandBuffer(cmd_, &bi));
  marks_ = 0;
  if (timestamps_) {
    vkCmdResetQueryPool(cmd_, timestamps_, 0, kMaxStageMarks + 2);
    vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps_, 0);
  }
  std::vector<const void*> owners;
  const std::uint32_t head = record_deferred(cmd_, owners);
  record(cmd_);
  // The CPU reads results straight from mapped memory after the fence:
  // make the kernels' and copies' writes visible to the host.
  VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
  vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &to_host, 0, nullptr, 0, nullptr);
  const std::uint32_t last = marks_ + 1;
  if (timestamps_) vkCmdWriteTimestamp(cmd_, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps_, last);
  ENGINE_VK_CHECK(vkEndCommandBuffer(cmd_));
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &cmd_;
  ENGINE_VK_CHECK(vkResetFences(device_, 1, &fence_));
  ENGINE_VK_CHECK(vkQueueSubmit(queue_, 1, &si, fence_));
  submissions_.fetch_add(1, std::memory_order_relaxed);
  ENGINE_VK_CHECK(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX));
  last_stage_ms_.clear();
  if (!timestamps_) return -1.0;
  std::uint64_t ticks[kMaxStageMarks + 2] = {};
  ENGINE_VK_CHECK(vkGetQueryPoolResults(device_, timestamps_, 0, last + 1, sizeof(ticks), ticks, sizeof(std::uint64_t),
                                        VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const double ms_per_tick = info_.timestamp_period_ns * 1e-6;
  const auto span_ms = [&](std::uint32_t a, std::uint32_t b) { return static_cast<double>(ticks[b] - ticks[a]) * ms_per_tick; };
  // The queued commands' marks first (when marks ran out, the rest of
  // theirs counts as the submission's own).
  for (std::uint32_t i = 1; i <= std::min(head, marks_); ++i) {
    const void* owner = owners[i - 1];
    auto at = std::find_if(deferred_ms_.begin(), deferred_ms_.end(), [&](const auto& t) { return t.first == owner; });
    if (at == deferred_ms_.end()) at = deferred_ms_.insert(deferred_ms_.end(), {owner, 0.0});
    at->second += span_ms(i - 1, i);
  }
  const std::uint32_t own_first = std::min(head, marks_);
  for (std::uint32_t i = own_first + 1; i <= last; ++i) last_stage_ms_.push_back(span_ms(i - 1, i));
  return span_ms(own_first, last);
}

void VulkanContext::mark_stage(VkCommandBuffer cmd) {
  if (!timestamps_ || marks_ >= kMaxStageMarks) return;
  ++marks_;
  vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps_, marks_);
}

}  // namespace engine::gpu
