#pragma once
// The real-time frame's probe lights on a Vulkan device
// (shaders/probe_lights.comp): probes::interpolate_fields_with for each
// network sample, written into buffers the fused decoder then reads. The
// CPU function is the oracle (tests/gpu/probe_lights_test.cpp).
#include <memory>
#include <span>
#include <string>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "probe_lights_shared.h"
#include "shading/probe_light_maker.h"

namespace transgi::gpu {

class VulkanProbeLights {
 public:
  explicit VulkanProbeLights(engine::gpu::VulkanContext& ctx);

  // Uploads the fields' maps, SH copies and boxes; false (why set) for more
  // than kProbeLightsMaxFields fields or none.
  bool set_probes(std::span<const probes::ProbeField* const> fields, int rotations, const shading::ProbeLightMaker::ShOf& sh,
                  std::string* why);
  // Room for n points (mapped), valid until the next call.
  std::span<shading::ProbeLightMaker::Point> points(std::size_t n);
  // Records the kernel: the n points' indirect light into `light` (n x 75)
  // and, with second, their direct light into `light2`.
  void record(VkCommandBuffer cmd, std::size_t n, bool second, const engine::gpu::GpuBuffer& light,
              const engine::gpu::GpuBuffer& light2);

 private:
  engine::gpu::VulkanContext& ctx_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
  engine::gpu::GpuBuffer points_, fields_, depth_, probes_, sh_, sh_at_;
  std::uint32_t field_count_ = 0, rotations_ = 0;
};

}  // namespace transgi::gpu
