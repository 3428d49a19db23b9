#pragma once
// One Vulkan instance, device and compute queue for the engine's compute
// passes. Create() returns null with a reason where no device can be had (no
// loader, no driver, no match for the requested name): callers and tests fall
// back to the CPU or skip, they do not crash. Every later failure throws
// GpuError naming the Vulkan call.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <vulkan/vulkan_core.h>

#include "engine/gpu/device_choice.h"

namespace engine::gpu {

struct GpuOptions {
  // Substring of the device name; empty: the ENGINE_GPU_DEVICE environment
  // variable, then the ranked default (device_choice.h).
  std::string device;
  // Khronos validation layer where installed. Default: on in debug builds,
  // where it costs nothing that matters; off in release, where it would slow
  // every call.
#ifdef NDEBUG
  bool validation = false;
#else
  bool validation = true;
#endif
};

struct DeviceInfo {
  std::string name;
  DeviceKind kind = DeviceKind::Other;
  std::string driver;       // "llvmpipe Mesa 22.3.6 (LLVM 15.0.6)"
  bool shader_float16 = false;
  std::uint32_t max_shared_memory = 0;
  double timestamp_period_ns = 0;  // 0: the queue has no timestamps
};

class VulkanContext {
 public:
  // Null and *why_not set when no usable device exists.
  static std::unique_ptr<VulkanContext> create(const GpuOptions& options, std::string* why_not);
  ~VulkanContext();
  VulkanContext(const VulkanContext&) = delete;
  VulkanContext& operator=(const VulkanContext&) = delete;

  [[nodiscard]] VkDevice device() const { return device_; }
  [[nodiscard]] VkPhysicalDevice physical_device() const { return physical_; }
  [[nodiscard]] const DeviceInfo& info() const { return info_; }
  // Validation-layer errors seen so far (0 without the layer); tests assert 0.
  [[nodiscard]] int validation_errors() const { return validation_errors_; }
  [[nodiscard]] bool validation_enabled() const { return messenger_ != VK_NULL_HANDLE; }

  // A memory type with these property flags among `type_bits`; throws
  // GpuError if there is none.
  [[nodiscard]] std::uint32_t memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags flags) const;

  // Records commands with `record`, submits them, waits. Returns the GPU
  // time between the first and last command in milliseconds (timestamps), or
  // -1 where the queue has none.
  double submit_and_wait(const std::function<void(VkCommandBuffer)>& record);

 private:
  VulkanContext() = default;
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                      VkDebugUtilsMessageTypeFlagsEXT,
                                                      const VkDebugUtilsMessengerCallbackDataEXT* data, void* self);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkQueryPool timestamps_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  int validation_errors_ = 0;
};

}  // namespace engine::gpu
