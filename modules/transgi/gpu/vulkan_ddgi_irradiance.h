#pragma once
// DDGI irradiance at many shading points in one dispatch
// (shaders/ddgi_irradiance.comp): the contract of ddgi::DdgiVolume::irradiance,
// its oracle (tests/gpu/ddgi_irradiance_test.cpp), so both methods' probe
// lookups run on one backend.
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "ddgi/ddgi_volume.h"
#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"

namespace transgi::gpu {

struct GpuDdgiIrradiance {
  std::vector<glm::vec3> irradiance;  // per point
  std::vector<std::uint8_t> lit;      // per point: some active probe weighed in
  double gpu_ms = -1;
};

class VulkanDdgiIrradiance {
 public:
  explicit VulkanDdgiIrradiance(engine::gpu::VulkanContext& ctx);

  // Uploads the volume's maps (every call: a frame loop would upload the
  // probes it blended) and evaluates each point.
  GpuDdgiIrradiance irradiance(const ddgi::DdgiVolume& volume, std::span<const glm::vec3> positions,
                               std::span<const glm::vec3> normals, std::span<const glm::vec3> view_dirs);

 private:
  engine::gpu::VulkanContext& ctx_;
  engine::gpu::GpuBuffer points_, irradiance_, distance_, placed_, result_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
};

}  // namespace transgi::gpu
