#pragma once
// A 2D image in device-local memory, with a view where one is asked for:
// the targets of a raster pass (VisibilityPass) and the game's frame before
// it is presented. Owns the image, its memory and its view; moves, never
// copies.
#include <cstdint>

#include <vulkan/vulkan_core.h>

namespace engine::gpu {

class VulkanContext;

class DeviceImage {
 public:
  DeviceImage() = default;
  // view_aspect: the aspect its view covers (colour or depth); 0: no view.
  DeviceImage(VulkanContext& ctx, std::uint32_t width, std::uint32_t height, VkFormat format, VkImageUsageFlags usage,
              VkImageAspectFlags view_aspect = 0);
  ~DeviceImage();
  DeviceImage(DeviceImage&& o) noexcept;
  DeviceImage& operator=(DeviceImage&& o) noexcept;
  DeviceImage(const DeviceImage&) = delete;
  DeviceImage& operator=(const DeviceImage&) = delete;

  [[nodiscard]] VkImage image() const { return image_; }
  [[nodiscard]] VkImageView view() const { return view_; }

 private:
  void destroy();
  VkDevice device_ = VK_NULL_HANDLE;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
};

}  // namespace engine::gpu
