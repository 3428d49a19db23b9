#include "engine/gpu/compute_pipeline.h"

#include <algorithm>
#include <string>
#include <utility>

#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/gpu_error.h"
#include "engine/gpu/vulkan_context.h"

namespace engine::gpu {

ComputePipeline::ComputePipeline(VulkanContext& ctx, std::span<const std::uint32_t> spirv,
                                 std::uint32_t storage_buffers, std::uint32_t push_constant_bytes)
    : ComputePipeline(ctx, spirv, std::vector<VkDescriptorType>(storage_buffers, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER),
                      push_constant_bytes) {}

ComputePipeline::ComputePipeline(VulkanContext& ctx, std::span<const std::uint32_t> spirv,
                                 std::vector<VkDescriptorType> bindings, std::uint32_t push_constant_bytes)
    : device_(ctx.device()), types_(std::move(bindings)), push_bytes_(push_constant_bytes) {
  const auto count = static_cast<std::uint32_t>(types_.size());
  VkShaderModuleCreateInfo smi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smi.codeSize = spirv.size_bytes();
  smi.pCode = spirv.data();
  ENGINE_VK_CHECK(vkCreateShaderModule(device_, &smi, nullptr, &module_));

  std::vector<VkDescriptorSetLayoutBinding> b(count);
  for (std::uint32_t i = 0; i < count; ++i) b[i] = {i, types_[i], 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo dli{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  dli.bindingCount = count;
  dli.pBindings = b.data();
  ENGINE_VK_CHECK(vkCreateDescriptorSetLayout(device_, &dli, nullptr, &set_layout_));

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_};
  VkPipelineLayoutCreateInfo pli{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &set_layout_;
  pli.pushConstantRangeCount = push_bytes_ ? 1 : 0;
  pli.pPushConstantRanges = &range;
  ENGINE_VK_CHECK(vkCreatePipelineLayout(device_, &pli, nullptr, &layout_));

  VkComputePipelineCreateInfo cpi{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  cpi.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  cpi.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  cpi.stage.module = module_;
  cpi.stage.pName = "main";
  cpi.layout = layout_;
  ENGINE_VK_CHECK(vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &cpi, nullptr, &pipeline_));

  std::vector<VkDescriptorPoolSize> sizes;
  for (const VkDescriptorType t : types_) {
    auto it = std::find_if(sizes.begin(), sizes.end(), [&](const VkDescriptorPoolSize& p) { return p.type == t; });
    if (it == sizes.end()) sizes.push_back({t, 1});
    else ++it->descriptorCount;
  }
  if (sizes.empty()) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1});
  VkDescriptorPoolCreateInfo dpi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dpi.maxSets = 1;
  dpi.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  dpi.pPoolSizes = sizes.data();
  ENGINE_VK_CHECK(vkCreateDescriptorPool(device_, &dpi, nullptr, &pool_));
  VkDescriptorSetAllocateInfo dai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dai.descriptorPool = pool_;
  dai.descriptorSetCount = 1;
  dai.pSetLayouts = &set_layout_;
  ENGINE_VK_CHECK(vkAllocateDescriptorSets(device_, &dai, &set_));
}

ComputePipeline::~ComputePipeline() {
  if (pool_) vkDestroyDescriptorPool(device_, pool_, nullptr);
  if (pipeline_) vkDestroyPipeline(device_, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(device_, layout_, nullptr);
  if (set_layout_) vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
  if (module_) vkDestroyShaderModule(device_, module_, nullptr);
}

void ComputePipeline::check_binding(std::uint32_t binding, VkDescriptorType type) const {
  if (binding >= types_.size())
    throw GpuError("ComputePipeline::bind: binding " + std::to_string(binding) + " of " + std::to_string(types_.size()));
  if (types_[binding] != type)
    throw GpuError("ComputePipeline::bind: binding " + std::to_string(binding) + " is of descriptor type " +
                   std::to_string(types_[binding]) + ", not " + std::to_string(type));
}

void ComputePipeline::bind(std::uint32_t binding, VkAccelerationStructureKHR structure) {
  check_binding(binding, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR);
  VkWriteDescriptorSetAccelerationStructureKHR as{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  as.accelerationStructureCount = 1;
  as.pAccelerationStructures = &structure;
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.pNext = &as;
  w.dstSet = set_;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  vkUpdateDescriptorSets(device_, 1, &w, 0, nullptr);
}

void ComputePipeline::bind(std::uint32_t binding, const GpuBuffer& buffer) {
  check_binding(binding, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  VkDescriptorBufferInfo info{buffer.handle(), 0, VK_WHOLE_SIZE};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set_;
  w.dstBinding = binding;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  w.pBufferInfo = &info;
  vkUpdateDescriptorSets(device_, 1, &w, 0, nullptr);
}

void ComputePipeline::record_dispatch(VkCommandBuffer cmd, std::uint32_t gx, std::uint32_t gy, std::uint32_t gz,
                                      const void* push) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
  if (push_bytes_) vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, push_bytes_, push);
  vkCmdDispatch(cmd, gx, gy, gz);
}

GpuBuffer& bind_at_least(VulkanContext& ctx, ComputePipeline& pipeline, std::uint32_t binding, GpuBuffer& buffer,
                         std::size_t bytes) {
  if (buffer.handle() == VK_NULL_HANDLE || buffer.size() < bytes) {
    buffer = GpuBuffer(ctx, bytes);
    pipeline.bind(binding, buffer);
  }
  return buffer;
}

void record_memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src,
                           VkPipelineStageFlags dst_stage, VkAccessFlags dst) {
  VkMemoryBarrier mb{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  mb.srcAccessMask = src;
  mb.dstAccessMask = dst;
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &mb, 0, nullptr, 0, nullptr);
}

void record_compute_barrier(VkCommandBuffer cmd) {
  record_memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                        VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
}

}  // namespace engine::gpu
