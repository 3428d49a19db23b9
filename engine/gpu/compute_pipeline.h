#pragma once
// One compute kernel: its SPIR-V, a descriptor set at set 0, bindings
// 0..N-1 (the kernel's declared inputs and outputs, in order: storage
// buffers, and where a kernel traces with ray queries, an acceleration
// structure), and a push-constant block. A pass binds buffers, then records
// a dispatch into a command buffer.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <vulkan/vulkan_core.h>

namespace engine::gpu {

class GpuBuffer;
class VulkanContext;

class ComputePipeline {
 public:
  ComputePipeline(VulkanContext& ctx, std::span<const std::uint32_t> spirv, std::uint32_t storage_buffers,
                  std::uint32_t push_constant_bytes);
  // Bindings of the given types (VK_DESCRIPTOR_TYPE_STORAGE_BUFFER or
  // VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR), in binding order.
  ComputePipeline(VulkanContext& ctx, std::span<const std::uint32_t> spirv, std::vector<VkDescriptorType> bindings,
                  std::uint32_t push_constant_bytes);
  ~ComputePipeline();
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  // Throws GpuError for a binding out of range.
  // Throws GpuError for a binding out of range or of another type.
  void bind(std::uint32_t binding, const GpuBuffer& buffer);
  void bind(std::uint32_t binding, VkAccelerationStructureKHR structure);
  // push: exactly push_constant_bytes.
  void record_dispatch(VkCommandBuffer cmd, std::uint32_t groups_x, std::uint32_t groups_y, std::uint32_t groups_z,
                       const void* push) const;

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorType> types_;
  std::uint32_t push_bytes_ = 0;
  void check_binding(std::uint32_t binding, VkDescriptorType type) const;
  VkShaderModule module_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

// `buffer` with at least `bytes`: kept if it is big enough, else replaced by
// a new one bound at `binding` (buffers grow with the batch, never shrink).
GpuBuffer& bind_at_least(VulkanContext& ctx, ComputePipeline& pipeline, std::uint32_t binding, GpuBuffer& buffer,
                         std::size_t bytes);

// Makes the writes of one dispatch visible to the reads of the next.
void record_compute_barrier(VkCommandBuffer cmd);

// One global memory barrier: `src` writes in `src_stage` become visible to
// `dst` accesses in `dst_stage` (and in later submissions).
void record_memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src,
                           VkPipelineStageFlags dst_stage, VkAccessFlags dst);

}  // namespace engine::gpu
