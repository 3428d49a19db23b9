#pragma once
// A frame's probe rays on a Vulkan device, in one submission: generated
// (shaders/probe_rays.comp), traced (rt_query.comp), their hits shaded up to
// the light sample's shadow ray (probe_hit_begin.comp: probes::begin_probe_ray),
// the shadow rays traced, and the rest (probe_hit_finish.comp:
// probes::finish_probe_ray, with the bounce light interpolated from the
// probe fields). Only the probes' origins go in and the shaded hits come
// out. The CPU functions are the oracle (tests/gpu/probe_shading_test.cpp);
// the light sample draws the same random numbers.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/gpu_ray_tracer.h"
#include "engine/gpu/gpu_shading_scene.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/render/light_set.h"
#include "engine/rt/ray_batch_tracer.h"
#include "probe_shading_shared.h"
#include "probes/probe_kernels.h"
#include "probes/probe_rays.h"

namespace transgi::gpu {

class VulkanMapStore;

// What a probe ray's hit needs for a bounce light the caller computes (DDGI's
// volumes): the hit's diffuse albedo / pi and shading normal, and whether it
// takes bounce light at all (not an emitter, the sky, or a back face).
struct BounceInput {
  glm::vec3 reflectance_over_pi{0.0f};
  glm::vec3 shading_normal{0.0f};
  bool takes_bounce = false;
};

// hit.radiance += reflectance_over_pi x bounce(hit.position, shading_normal,
// -direction), as probes::finish_probe_ray adds its feedback, non-finite
// sums replaced by 0 and counted; a ray the device already found
// non-finite stays 0.
template <class Bounce>
void finish_bounce_light(probes::ProbeRayHit& hit, const BounceInput& in, const glm::vec3& direction, Bounce&& bounce) {
  if (!in.takes_bounce || hit.replaced_non_finite) return;
  hit.radiance += in.reflectance_over_pi * bounce(hit.position, in.shading_normal, -direction);
  if (!std::isfinite(hit.radiance.r + hit.radiance.g + hit.radiance.b)) {
    hit.radiance = glm::vec3(0.0f);
    hit.replaced_non_finite = true;
  }
}

class VulkanProbeShading {
 public:
  // Throws GpuError where a kernel cannot be made.
  explicit VulkanProbeShading(engine::gpu::VulkanContext& ctx);

  // Whether `ctx`'s device can run the kernels (64-bit integers for the
  // random numbers); why not in *why.
  static bool supported(const engine::gpu::VulkanContext& ctx, std::string* why);

  // The rays of probes origins[j] (probe index probe_ids[j]) along each of
  // `directions`, traced and shaded as trace_probe_rays does with
  // generator make_rng(seed, probe_ids[j] * 4096 + i, sample) for ray i, the
  // bounce light `self`'s irradiance inside its grid's box and `outer`'s
  // beyond it (either null: none). out: origins.size() x directions.size(),
  // probe-major. Returns false, out untouched, where the tracer declines the
  // scene.
  // With `bounce_inputs` (and no fields), the bounce light is the caller's:
  // each ray gets what it needs to add it (finish_bounce_light). With
  // `brief`, only what the host needs where the hits stay on the device for
  // the raster (probe_points.comp) comes back: each ray's hit, back-face,
  // saw-light and non-finite flags, distance and emission (20 bytes, not
  // 64); its position, normal and radiance are left zero.
  bool shade(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, engine::gpu::GpuRayTracer& tracer,
             std::span<const glm::vec3> origins, std::span<const int> probe_ids, std::span<const glm::vec3> directions,
             std::uint64_t seed, std::uint64_t sample, const probes::ProbeFeedbackSource* self,
             const probes::ProbeFeedbackSource* outer, std::vector<probes::ProbeRayHit>& out,
             std::vector<BounceInput>* bounce_inputs = nullptr, bool brief = false);

  // shade() in three steps, for a submission that holds other stages too:
  // prepare (false where the tracer declines the scene), record into the
  // submission, then read once it ran (the brief and bounce_inputs as
  // shade's).
  bool prepare(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, engine::gpu::GpuRayTracer& tracer,
               std::span<const glm::vec3> origins, std::span<const int> probe_ids, std::span<const glm::vec3> directions,
               std::uint64_t seed, std::uint64_t sample, const probes::ProbeFeedbackSource* self,
               const probes::ProbeFeedbackSource* outer);
  void record(VkCommandBuffer cmd) const;
  // With `brief`, `emission` false leaves each hit's emission zero and
  // reads 8 bytes a ray instead of 20.
  void read(std::vector<probes::ProbeRayHit>& out, std::vector<BounceInput>* bounce_inputs = nullptr, bool brief = false,
            bool emission = true) const;
  // Device milliseconds to count for the shading (a caller that records it
  // in a submission of its own times it).
  void add_gpu_ms(double ms) { gpu_ms_ += std::max(0.0, ms); }

  // The last shade()'s results on the device (ProbeRayHitGpu per ray, in
  // `out`'s order) and its directions (vec4 each), until the next shade().
  [[nodiscard]] const engine::gpu::GpuBuffer& hits_on_device() const { return out_; }
  [[nodiscard]] const engine::gpu::GpuBuffer& directions_on_device() const { return directions_; }

  [[nodiscard]] double take_gpu_ms() {
    const double ms = gpu_ms_;
    gpu_ms_ = 0;
    return ms;
  }

 private:
  engine::gpu::VulkanContext& ctx_;
  engine::gpu::GpuShadingScene scene_;
  std::unique_ptr<engine::gpu::ComputePipeline> generate_, trace_, begin_, shadow_trace_, finish_;
  engine::gpu::GpuBuffer origins_, directions_, rays_, hits_, items_, pending_, shadows_, shadow_hits_;
  engine::gpu::GpuBuffer out_, briefs_, emission_, feedback_, probes_, probe_sh_;
  // Both fields' depth maps on the device, filled in the submission: from
  // a field's VulkanMapStore (a copy on the device) or from the host
  // through depth_staging_.
  engine::gpu::GpuBuffer depth_, depth_staging_;
  double gpu_ms_ = 0;
  // What prepare left for record and read.
  struct Prepared {
    std::size_t rays = 0, m = 0;
    ProbeHitPush push{};
    VulkanMapStore* stores[2] = {nullptr, nullptr};
    std::vector<VkBufferCopy> host_depth, store_depth[2];
  };
  Prepared prepared_;
};

}  // namespace transgi::gpu
