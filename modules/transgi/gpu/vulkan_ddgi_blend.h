#pragma once
// DDGI's per-probe blending for every probe in one dispatch
// (shaders/ddgi_blend.comp): the contract of ddgi::blend_irradiance and
// blend_distance, its oracle (tests/gpu/ddgi_blend_test.cpp).
#include <memory>
#include <vector>

#include "ddgi/ddgi_blend.h"
#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"

namespace transgi::gpu {

class VulkanDdgiBlend {
 public:
  explicit VulkanDdgiBlend(engine::gpu::VulkanContext& ctx);

  // Blends records[q] into irradiance[q] and distance[q] for every probe
  // with records (every record list settings.rays_per_probe long; an empty
  // one leaves the probe as it is). Returns the kernel's GPU ms.
  double blend(std::vector<ddgi::OctahedralMap<glm::vec3>>& irradiance, std::vector<ddgi::OctahedralMap<glm::vec2>>& distance,
               const std::vector<std::vector<ddgi::RayRecord>>& records, const ddgi::DdgiSettings& settings,
               float hysteresis, bool clamp_brightness, float max_distance);

 private:
  engine::gpu::VulkanContext& ctx_;
  engine::gpu::GpuBuffer rays_, irradiance_, distance_, flags_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
};

}  // namespace transgi::gpu
