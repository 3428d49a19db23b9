#pragma once
// A storage buffer. Mapped (the default): the CPU writes and reads it
// directly, in the memory that BufferMemory names; for data that changes
// every frame. DeviceOnly: device-local memory, written through a staging
// copy; for data that kernels read many times and the CPU rarely changes (BVH,
// triangles, weights), which a discrete GPU would otherwise fetch over PCIe
// (on an H100 the level's probe and G-buffer rays traced in 2.69 ms from host
// memory, 1.13 from device memory). Where device memory is also mappable
// (lavapipe, integrated GPUs) a DeviceOnly buffer is simply mapped.
#include <cstddef>
#include <cstring>
#include <span>
#include <type_traits>

#include <vulkan/vulkan_core.h>

namespace engine::gpu {

class VulkanContext;

class GpuBuffer {
 public:
  enum class Placement { Mapped, DeviceOnly };

  GpuBuffer() = default;
  // bytes 0 is rounded up to 4. extra_usage: beyond storage and transfer,
  // e.g. what an acceleration structure's build reads; with
  // VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT the buffer has a
  // device_address().
  GpuBuffer(VulkanContext& ctx, std::size_t bytes, Placement placement = Placement::Mapped,
            VkBufferUsageFlags extra_usage = 0);
  ~GpuBuffer();
  GpuBuffer(GpuBuffer&& o) noexcept;
  GpuBuffer& operator=(GpuBuffer&& o) noexcept;
  GpuBuffer(const GpuBuffer&) = delete;
  GpuBuffer& operator=(const GpuBuffer&) = delete;

  [[nodiscard]] VkBuffer handle() const { return buffer_; }
  [[nodiscard]] std::size_t size() const { return bytes_; }
  // Throws GpuError unless made with VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT.
  [[nodiscard]] VkDeviceAddress device_address() const;
  // The mapped memory as `count` T's, for callers that fill or read it in
  // parallel without a copy. Throws GpuError on an unmapped buffer or one
  // too small.
  // The span counts as traffic (VulkanContext::traffic): read from the
  // device where T is const, written to it otherwise.
  template <class T>
  [[nodiscard]] std::span<T> mapped_as(std::size_t count) const {
    check_mapped(count * sizeof(T));
    count_traffic(count * sizeof(T), std::is_const_v<T>);
    return {static_cast<T*>(mapped_), count};
  }

  // Throws GpuError if the data does not fit. On an unmapped DeviceOnly
  // buffer each call is a staging copy that waits for the queue: never call
  // it while commands are being recorded.
  template <class T>
  void upload(std::span<const T> data) { write_bytes(data.data(), data.size_bytes()); }
  template <class T>
  void download(std::span<T> out) const { read_bytes(out.data(), out.size_bytes()); }

 private:
  void write_bytes(const void* src, std::size_t n);
  void read_bytes(void* dst, std::size_t n) const;
  void release();
  void check_mapped(std::size_t bytes) const;
  void count_traffic(std::size_t bytes, bool device_to_host) const;

  VulkanContext* ctx_ = nullptr;
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  std::size_t bytes_ = 0;
  bool addressable_ = false;
};

// Throws GpuError, "<owner>: the scene's <what> take X MiB, more than the
// device's largest storage buffer (Y MiB)", where `bytes` is more than a
// kernel can bind on ctx's device (its owner then runs the work on the CPU:
// a device would read past the binding's end).
void require_storage_range(const VulkanContext& ctx, std::size_t bytes, const char* owner, const char* what);

}  // namespace engine::gpu
