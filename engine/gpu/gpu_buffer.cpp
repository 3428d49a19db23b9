#include "engine/gpu/gpu_buffer.h"

#include <string>
#include <utility>

#include "engine/gpu/gpu_error.h"
#include "engine/gpu/vulkan_context.h"

namespace engine::gpu {

GpuBuffer::GpuBuffer(VulkanContext& ctx, std::size_t bytes) : device_(ctx.device()), bytes_(bytes < 4 ? 4 : bytes) {
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = bytes_;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ENGINE_VK_CHECK(vkCreateBuffer(device_, &bci, nullptr, &buffer_));
  try {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buffer_, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    mai.memoryTypeIndex =
        ctx.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    ENGINE_VK_CHECK(vkAllocateMemory(device_, &mai, nullptr, &memory_));
    ENGINE_VK_CHECK(vkBindBufferMemory(device_, buffer_, memory_, 0));
    ENGINE_VK_CHECK(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
  } catch (...) {
    release();
    throw;
  }
}

GpuBuffer::~GpuBuffer() { release(); }

GpuBuffer::GpuBuffer(GpuBuffer&& o) noexcept { *this = std::move(o); }

GpuBuffer& GpuBuffer::operator=(GpuBuffer&& o) noexcept {
  if (this != &o) {
    release();
    device_ = std::exchange(o.device_, VK_NULL_HANDLE);
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    mapped_ = std::exchange(o.mapped_, nullptr);
    bytes_ = std::exchange(o.bytes_, 0);
  }
  return *this;
}

void GpuBuffer::release() {
  if (!device_) return;
  if (mapped_) vkUnmapMemory(device_, memory_);
  if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);
  device_ = VK_NULL_HANDLE;
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

void GpuBuffer::write_bytes(const void* src, std::size_t n) {
  if (n > bytes_) throw GpuError("GpuBuffer: upload of " + std::to_string(n) + " bytes into " + std::to_string(bytes_));
  if (n) std::memcpy(mapped_, src, n);
}

void GpuBuffer::read_bytes(void* dst, std::size_t n) const {
  if (n > bytes_) throw GpuError("GpuBuffer: download of " + std::to_string(n) + " bytes from " + std::to_string(bytes_));
  if (n) std::memcpy(dst, mapped_, n);
}

}  // namespace engine::gpu
