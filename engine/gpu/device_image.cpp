#include "engine/gpu/device_image.h"

#include <utility>

#include "engine/gpu/gpu_error.h"
#include "engine/gpu/vulkan_context.h"

namespace engine::gpu {

DeviceImage::DeviceImage(VulkanContext& ctx, std::uint32_t width, std::uint32_t height, VkFormat format, VkImageUsageFlags usage,
                         VkImageAspectFlags view_aspect)
    : device_(ctx.device()) {
  VkImageCreateInfo ici{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = VK_IMAGE_TYPE_2D;
  ici.format = format;
  ici.extent = {width, height, 1};
  ici.mipLevels = 1;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = usage;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  try {
    ENGINE_VK_CHECK(vkCreateImage(device_, &ici, nullptr, &image_));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device_, image_, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = ctx.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    ENGINE_VK_CHECK(vkAllocateMemory(device_, &mai, nullptr, &memory_));
    ENGINE_VK_CHECK(vkBindImageMemory(device_, image_, memory_, 0));
    if (view_aspect != 0) {
      VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      vci.image = image_;
      vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
      vci.format = format;
      vci.subresourceRange = {view_aspect, 0, 1, 0, 1};
      ENGINE_VK_CHECK(vkCreateImageView(device_, &vci, nullptr, &view_));
    }
  } catch (...) {
    destroy();
    throw;
  }
}

DeviceImage::~DeviceImage() { destroy(); }

DeviceImage::DeviceImage(DeviceImage&& o) noexcept
    : device_(o.device_),
      image_(std::exchange(o.image_, VK_NULL_HANDLE)),
      memory_(std::exchange(o.memory_, VK_NULL_HANDLE)),
      view_(std::exchange(o.view_, VK_NULL_HANDLE)) {}

DeviceImage& DeviceImage::operator=(DeviceImage&& o) noexcept {
  if (this != &o) {
    destroy();
    device_ = o.device_;
    image_ = std::exchange(o.image_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    view_ = std::exchange(o.view_, VK_NULL_HANDLE);
  }
  return *this;
}

void DeviceImage::destroy() {
  if (view_) vkDestroyImageView(device_, view_, nullptr);
  if (image_) vkDestroyImage(device_, image_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
}

}  // namespace engine::gpu
