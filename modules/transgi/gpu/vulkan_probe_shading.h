#pragma once
// Probe-ray hit shading on a Vulkan device (shaders/probe_hit_begin.comp,
// probe_hit_finish.comp): probes::begin_probe_ray, the shadow rays, and
// probes::finish_probe_ray with the bounce light interpolated from the probe
// fields, for a batch of rays the device has traced. The CPU functions are
// the oracle (tests/gpu/probe_shading_test.cpp); the light sample draws the
// same random numbers.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/gpu_shading_scene.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/render/light_set.h"
#include "engine/rt/ray_batch_tracer.h"
#include "probes/probe_kernels.h"
#include "probes/probe_rays.h"

namespace transgi::gpu {

class VulkanProbeShading {
 public:
  // Throws GpuError where a kernel cannot be made.
  explicit VulkanProbeShading(engine::gpu::VulkanContext& ctx);

  // Whether `ctx`'s device can run the kernels (64-bit integers for the
  // random numbers); why not in *why.
  static bool supported(const engine::gpu::VulkanContext& ctx, std::string* why);

  // Shades rays[k] (whose closest hits `tracer` finds) as
  // shade_probe_ray(scene, lights, dir, hit, make_rng(seed, items[k], sample),
  // feedback) does, feedback being `self`'s irradiance inside its box and
  // `outer`'s outside it (either may be null: no light). Returns false, out
  // untouched, where the tracer declines the scene.
  bool shade(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
             engine::rt::RayBatchTracer& tracer, std::span<const engine::rt::Ray> rays,
             std::span<const std::uint64_t> items, std::uint64_t seed, std::uint64_t sample,
             const probes::ProbeFeedbackSource* self, const probes::ProbeFeedbackSource* outer,
             std::vector<probes::ProbeRayHit>& out);

  [[nodiscard]] double take_gpu_ms() {
    const double ms = gpu_ms_;
    gpu_ms_ = 0;
    return ms;
  }

 private:
  engine::gpu::VulkanContext& ctx_;
  engine::gpu::GpuShadingScene scene_;
  std::unique_ptr<engine::gpu::ComputePipeline> begin_, finish_;
  engine::gpu::GpuBuffer rays_, hits_, items_, pending_, shadows_;
  engine::gpu::GpuBuffer blocked_, out_, feedback_, depth_, probes_, probe_sh_;
  double gpu_ms_ = 0;
};

}  // namespace transgi::gpu
