#pragma once
// probes::update_own_depth on the device (shaders/probe_own_depth.comp):
// each batch probe's depth map in its field's VulkanMapStore updated from
// its own rays as the probe shading left them on the device, bit for bit as
// the host updates its own copy, so that neither goes over the bus.
#include <memory>
#include <span>
#include <vector>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "probe_shading_shared.h"
#include "probes/probe_map.h"

namespace transgi::gpu {

class VulkanProbeOwnDepth {
 public:
  explicit VulkanProbeOwnDepth(engine::gpu::VulkanContext& ctx);

  // The probes[k] records and their rays: hits (ProbeRayHitGpu per ray) and
  // directions (vec4 per direction, rays_per_probe of them) as the shading
  // left them; `depth`: the store's depth maps, updated in place.
  void prepare(std::span<const OwnDepthProbeGpu> probes, const engine::gpu::GpuBuffer& hits,
               const engine::gpu::GpuBuffer& directions, const engine::gpu::GpuBuffer& depth, std::uint32_t rays_per_probe,
               const probes::MapLayout& layout);
  // The dispatch, into a submission being recorded (after the shading's,
  // before the kernels that read the depth).
  void record(VkCommandBuffer cmd) const;

 private:
  engine::gpu::VulkanContext& ctx_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
  engine::gpu::GpuBuffer probes_;
  OwnDepthPush push_{};
};

}  // namespace transgi::gpu
