#pragma once
// Probe interpolation with pruning for many shading points in one dispatch
// (shaders/probe_interpolation.comp): the contract of
// probes::interpolate_probes, plus the blended light SH per point. The CPU
// function is its oracle (tests/gpu/probe_interpolation_test.cpp).
//
// Each call uploads the probes' depth maps whole (512 probes of 100 x 50
// texels: 10 MB). A frame loop would upload only the probes that changed;
// that comes with the GPU-resident probe field.
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "probes/interpolation.h"

namespace transgi::gpu {

struct GpuInterpolation {
  std::vector<probes::InterpolationResult> results;  // per point
  std::vector<float> light_sh;                        // per point, 75 [c * 25 + k]
  double gpu_ms = -1;
};

class VulkanProbeInterpolator {
 public:
  VulkanProbeInterpolator(engine::gpu::VulkanContext& ctx, probes::MapLayout layout);

  // probe_sh: grid.count() x 75; usable: empty (all) or grid.count() flags;
  // positions and normals: one per point; viewer: theirs, or null.
  GpuInterpolation interpolate(const probes::ProbeGrid& grid, const std::vector<probes::ProbeMapState>& states,
                               std::span<const float> probe_sh, std::span<const std::uint8_t> usable,
                               const probes::InterpolationSettings& settings, std::span<const glm::vec3> positions,
                               std::span<const glm::vec3> normals, const glm::vec3* viewer = nullptr);

 private:
  engine::gpu::VulkanContext& ctx_;
  probes::MapLayout layout_;
  engine::gpu::GpuBuffer points_, depth_, probes_, probe_sh_, results_, point_sh_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
};

}  // namespace transgi::gpu
