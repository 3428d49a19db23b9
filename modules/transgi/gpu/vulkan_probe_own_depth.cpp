#include "gpu/vulkan_probe_own_depth.h"

#include "gpu/shader_path.h"

namespace transgi::gpu {

VulkanProbeOwnDepth::VulkanProbeOwnDepth(engine::gpu::VulkanContext& ctx) : ctx_(ctx) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("probe_own_depth.comp"), 4,
                                                              static_cast<std::uint32_t>(sizeof(OwnDepthPush)));
}

void VulkanProbeOwnDepth::prepare(std::span<const OwnDepthProbeGpu> probes, const engine::gpu::GpuBuffer& hits,
                                  const engine::gpu::GpuBuffer& directions, const engine::gpu::GpuBuffer& depth,
                                  std::uint32_t rays_per_probe, const probes::MapLayout& layout) {
  push_ = {static_cast<uint>(probes.size()), rays_per_probe, static_cast<uint>(layout.width), static_cast<uint>(layout.height)};
  if (probes.empty()) return;
  engine::gpu::bind_at_least(ctx_, *pipeline_, 2, probes_, probes.size_bytes()).upload(probes);
  pipeline_->bind(0, hits);
  pipeline_->bind(1, directions);
  pipeline_->bind(2, probes_);
  pipeline_->bind(3, depth);
}

void VulkanProbeOwnDepth::record(VkCommandBuffer cmd) const {
  if (push_.count == 0) return;
  pipeline_->record_dispatch(cmd, (push_.count + 63) / 64, 1, 1, &push_);
}

}  // namespace transgi::gpu
