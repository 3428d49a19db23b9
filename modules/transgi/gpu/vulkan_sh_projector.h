#pragma once
// SH projection of many probes' radiance maps in one dispatch
// (shaders/sh_projection.comp): the contract of probes::MapProjector::project,
// which is its oracle (tests/gpu/sh_projection_test.cpp).
#include <memory>
#include <span>

#include <glm/glm.hpp>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "probes/radiance_map.h"

namespace transgi::gpu {

class VulkanShProjector {
 public:
  VulkanShProjector(engine::gpu::VulkanContext& ctx, const probes::MapProjector& projector);

  // radiance: probes x texel_count() values; out: probes x 75 [c * 25 + k].
  // Returns the kernel's GPU time in ms (-1 without timestamps).
  double project(std::span<const glm::vec3> radiance, std::span<float> out);
  // The same for maps already on the device: records the projection of
  // `probes` maps held in `radiance` (probes x texel_count() x 3 floats)
  // into cmd; read(out) takes the result after the submission completes.
  void record(VkCommandBuffer cmd, const engine::gpu::GpuBuffer& radiance, std::size_t probes);
  void read(std::span<float> out);

 private:
  engine::gpu::VulkanContext& ctx_;
  int texels_ = 0;
  engine::gpu::GpuBuffer basis_, radiance_, out_;
  std::size_t capacity_ = 0, out_capacity_ = 0, recorded_ = 0;
  // out_ with room for `probes` probes' coefficients, bound.
  void reserve_out(std::size_t probes);
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
};

}  // namespace transgi::gpu
