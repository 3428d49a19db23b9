#pragma once
// A storage buffer the CPU writes and reads directly (host-visible, coherent).
// On lavapipe and integrated GPUs that is the memory there is; on a discrete
// GPU kernels would read it over PCIe, so device-local copies are the next
// step once a GPU is there to measure them (shaders/README.md).
#include <cstddef>
#include <cstring>
#include <span>

#include <vulkan/vulkan_core.h>

namespace engine::gpu {

class VulkanContext;

class GpuBuffer {
 public:
  GpuBuffer() = default;
  GpuBuffer(VulkanContext& ctx, std::size_t bytes);  // bytes 0 is rounded up to 4
  ~GpuBuffer();
  GpuBuffer(GpuBuffer&& o) noexcept;
  GpuBuffer& operator=(GpuBuffer&& o) noexcept;
  GpuBuffer(const GpuBuffer&) = delete;
  GpuBuffer& operator=(const GpuBuffer&) = delete;

  [[nodiscard]] VkBuffer handle() const { return buffer_; }
  [[nodiscard]] std::size_t size() const { return bytes_; }

  // Throws GpuError if the data does not fit.
  template <class T>
  void upload(std::span<const T> data) { write_bytes(data.data(), data.size_bytes()); }
  template <class T>
  void download(std::span<T> out) const { read_bytes(out.data(), out.size_bytes()); }

 private:
  void write_bytes(const void* src, std::size_t n);
  void read_bytes(void* dst, std::size_t n) const;
  void release();

  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  std::size_t bytes_ = 0;
};

}  // namespace engine::gpu
