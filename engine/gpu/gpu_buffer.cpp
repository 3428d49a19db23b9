#include "engine/gpu/gpu_buffer.h"

#include <cstdio>

#include <string>
#include <utility>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_error.h"
#include "engine/gpu/vulkan_context.h"

namespace engine::gpu {

GpuBuffer::GpuBuffer(VulkanContext& ctx, std::size_t bytes, Placement placement, VkBufferUsageFlags extra_usage)
    : ctx_(&ctx), device_(ctx.device()), bytes_(bytes < 4 ? 4 : bytes),
      addressable_((extra_usage & VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT) != 0) {
  VkBufferCreateInfo bci{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = bytes_;
  bci.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
              extra_usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ENGINE_VK_CHECK(vkCreateBuffer(device_, &bci, nullptr, &buffer_));
  try {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device_, buffer_, &req);
    VkMemoryAllocateInfo mai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    mai.allocationSize = req.size;
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    if (addressable_) mai.pNext = &flags;
    const auto types = ctx.buffer_memory_types(req.memoryTypeBits, placement == Placement::Mapped);
    if (types.empty()) throw GpuError("no Vulkan memory type for a storage buffer on " + ctx.info().name);
    // A small BAR heap (256 MB without resizable BAR) fills up: the next
    // type, host memory, still works, only slower.
    VkResult r = VK_ERROR_OUT_OF_DEVICE_MEMORY;
    for (std::size_t t = 0; t < types.size() && r != VK_SUCCESS; ++t) {
      mai.memoryTypeIndex = types[t];
      r = vkAllocateMemory(device_, &mai, nullptr, &memory_);
      if (r != VK_SUCCESS && r != VK_ERROR_OUT_OF_DEVICE_MEMORY && r != VK_ERROR_OUT_OF_HOST_MEMORY) break;
    }
    if (r != VK_SUCCESS) throw GpuError("vkAllocateMemory of " + std::to_string(req.size) + " bytes failed: " + vk_result_name(r));
    ENGINE_VK_CHECK(vkBindBufferMemory(device_, buffer_, memory_, 0));
    VkPhysicalDeviceMemoryProperties mem;
    vkGetPhysicalDeviceMemoryProperties(ctx.physical_device(), &mem);
    constexpr VkMemoryPropertyFlags kMappable = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    const bool stage = placement == Placement::DeviceOnly && ctx.info().stage_device_only;
    if ((mem.memoryTypes[mai.memoryTypeIndex].propertyFlags & kMappable) == kMappable && !stage)
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
    ctx_ = std::exchange(o.ctx_, nullptr);
    device_ = std::exchange(o.device_, VK_NULL_HANDLE);
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    mapped_ = std::exchange(o.mapped_, nullptr);
    bytes_ = std::exchange(o.bytes_, 0);
    addressable_ = std::exchange(o.addressable_, false);
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

VkDeviceAddress GpuBuffer::device_address() const {
  if (!addressable_) throw GpuError("GpuBuffer: device_address of a buffer made without VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT");
  VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  info.buffer = buffer_;
  return vkGetBufferDeviceAddress(device_, &info);
}

void GpuBuffer::check_mapped(std::size_t bytes) const {
  if (!mapped_) throw GpuError("GpuBuffer: mapped_as on a buffer the CPU cannot map");
  if (bytes > bytes_) throw GpuError("GpuBuffer: mapped_as of " + std::to_string(bytes) + " bytes in " + std::to_string(bytes_));
}

void GpuBuffer::count_traffic(std::size_t bytes, bool device_to_host) const {
  if (!ctx_) return;
  if (device_to_host)
    ctx_->count_device_to_host(bytes);
  else
    ctx_->count_host_to_device(bytes);
}

void GpuBuffer::write_bytes(const void* src, std::size_t n) {
  if (n > bytes_) throw GpuError("GpuBuffer: upload of " + std::to_string(n) + " bytes into " + std::to_string(bytes_));
  if (!n) return;
  ctx_->count_host_to_device(n);
  if (mapped_) {
    std::memcpy(mapped_, src, n);
    return;
  }
  GpuBuffer staging(*ctx_, n);
  std::memcpy(staging.mapped_, src, n);
  const VkBufferCopy region{0, 0, n};
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) {
    vkCmdCopyBuffer(cmd, staging.buffer_, buffer_, 1, &region);
    // Later submissions' kernels and copies see the data.
    record_memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT);
  });
}

void GpuBuffer::read_bytes(void* dst, std::size_t n) const {
  if (n > bytes_) throw GpuError("GpuBuffer: download of " + std::to_string(n) + " bytes from " + std::to_string(bytes_));
  if (!n) return;
  ctx_->count_device_to_host(n);
  if (mapped_) {
    std::memcpy(dst, mapped_, n);
    return;
  }
  GpuBuffer staging(*ctx_, n);
  const VkBufferCopy region{0, 0, n};
  ctx_->submit_and_wait([&](VkCommandBuffer cmd) {
    record_memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_TRANSFER_READ_BIT);
    vkCmdCopyBuffer(cmd, buffer_, staging.buffer_, 1, &region);  // submit_and_wait makes it visible to the host
  });
  std::memcpy(dst, staging.mapped_, n);
}

void require_storage_range(const VulkanContext& ctx, std::size_t bytes, const char* owner, const char* what) {
  const std::uint64_t limit = ctx.info().max_storage_buffer_range;
  if (limit == 0 || bytes <= limit) return;
  const auto mebibytes = [](std::uint64_t b) {
    char text[32];
    std::snprintf(text, sizeof(text), "%.2f MiB", static_cast<double>(b) / (1024.0 * 1024.0));
    return std::string(text);
  };
  throw GpuError(std::string(owner) + ": the scene's " + what + " take " + mebibytes(bytes) +
                 ", more than the device's largest storage buffer (" + mebibytes(limit) + ")");
}

}  // namespace engine::gpu
