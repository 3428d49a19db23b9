#pragma once
// TransGI's accumulation on a Vulkan device (shaders/probe_accumulation.comp):
// probes::accumulate and probes::filled_radiance for every updated probe in
// one dispatch. The CPU functions are the oracle
// (tests/gpu/probe_accumulation_test.cpp).
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "probes/probe_map.h"

namespace transgi::gpu {

class VulkanProbeAccumulator {
 public:
  VulkanProbeAccumulator(engine::gpu::VulkanContext& ctx, probes::MapLayout layout);

  // For each i: accumulate(*states[i], *frames[i], settings) (changed[i] its
  // result) and filled_radiance(*states[i], layout, settings.fill_passes)
  // into filled (states.size() x texel_count()). Returns the GPU time in ms
  // (-1 without timestamps).
  double accumulate(std::span<probes::ProbeMapState* const> states, std::span<const probes::FrameSamples* const> frames,
                    const probes::AccumulationSettings& settings, std::span<std::uint8_t> changed,
                    std::span<glm::vec3> filled);

 private:
  engine::gpu::VulkanContext& ctx_;
  probes::MapLayout layout_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
  engine::gpu::GpuBuffer states_, history_, sampled_, frame_, filled_, solid_angle_, known_;
};

}  // namespace transgi::gpu
