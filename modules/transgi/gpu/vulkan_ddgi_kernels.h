#pragma once
// DDGI's probe rays and blend on a Vulkan device (ddgi::DdgiKernels).
#include <algorithm>
#include <exception>
#include <memory>
#include <string>

#include "ddgi/ddgi_kernels.h"
#include "ddgi/ddgi_plugin.h"
#include "ddgi/cpu_ddgi_kernels.h"
#include "ddgi/ddgi_renderer.h"
#include "engine/gpu/gpu_ray_tracer.h"
#include "gpu/vulkan_ddgi_blend.h"
#include "gpu/vulkan_ddgi_irradiance.h"
#include "gpu/vulkan_probe_shading.h"
#include "engine/gpu/gpu_error.h"
#include "engine/jobs/parallel_for.h"

namespace transgi::gpu {

class VulkanDdgiKernels : public ddgi::DdgiKernels {
 public:
  // Throws where a kernel cannot be made (make_ddgi_backend checks the
  // device's capabilities first).
  explicit VulkanDdgiKernels(std::shared_ptr<engine::gpu::VulkanContext> ctx)
      : ctx_(std::move(ctx)), tracer_(*ctx_), blend_(*ctx_), shading_(*ctx_), name_(engine::gpu::describe(ctx_->info())) {}

  // Traced and shaded on the device (VulkanProbeShading); the bounce light
  // from DDGI's volumes is added here, on the CPU, where the volumes are.
  void shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                        std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                        std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                        const ddgi::ProbeRayBounce& bounce, const ddgi::ProbeRayConsumer& consume) override {
    std::vector<probes::ProbeRayHit> out;
    std::vector<BounceInput> inputs;
    if (!shading_.shade(scene, lights, tracer_, origins, probe_ids, directions, seed, sample, nullptr, nullptr, out, &inputs))
      throw engine::gpu::GpuError("the Vulkan backend traces only scenes built with their assets (RtScene::assets())");
    const std::size_t m = directions.size();
    engine::jobs::parallel_for(0, static_cast<int>(origins.size()), 1, [&](int b, int e) {
      for (int j = b; j < e; ++j)
        for (std::size_t i = 0; i < m; ++i) {
          const std::size_t k = static_cast<std::size_t>(j) * m + i;
          finish_bounce_light(out[k], inputs[k], directions[i], bounce);
          consume(j, static_cast<int>(i), out[k]);
        }
    });
  }

  engine::rt::RayBatchTracer* tracer() override { return &tracer_; }
  void blend(std::vector<ddgi::OctahedralMap<glm::vec3>>& irradiance, std::vector<ddgi::OctahedralMap<glm::vec2>>& distance,
             const std::vector<std::vector<ddgi::RayRecord>>& records, const ddgi::DdgiSettings& settings, float hysteresis,
             bool clamp_brightness, float max_distance) override {
    blend_.blend(irradiance, distance, records, settings, hysteresis, clamp_brightness, max_distance);
  }
  // Each volume's lookups in one batch (its emitted maps' in a second,
  // through its emitted view), blended on the CPU as the CPU backend blends
  // them.
  void irradiance(std::span<const ddgi::DdgiVolume* const> volumes, std::span<const glm::vec3> positions,
                  std::span<const glm::vec3> normals, std::span<const glm::vec3> view_dirs,
                  std::span<glm::mat2x3> out) override {
    std::vector<std::vector<glm::mat2x3>> value(volumes.size(), std::vector<glm::mat2x3>(positions.size(), glm::mat2x3(0.0f)));
    std::vector<std::vector<std::uint8_t>> lit(volumes.size());
    for (std::size_t v = 0; v < volumes.size(); ++v) {
      GpuDdgiIrradiance r = irradiance_.irradiance(*volumes[v], positions, normals, view_dirs);
      for (std::size_t k = 0; k < positions.size(); ++k) value[v][k][0] = r.irradiance[k];
      lit[v] = std::move(r.lit);
      if (!volumes[v]->has_emitted_maps()) continue;
      const GpuDdgiIrradiance emitted = irradiance_.irradiance(volumes[v]->emitted_view(), positions, normals, view_dirs);
      for (std::size_t k = 0; k < positions.size(); ++k) value[v][k][1] = emitted.irradiance[k];
    }
    ddgi::mix_volume_batches(volumes, positions, value, lit, out);
  }
  engine::image::ImageRGB render_gi(const engine::rt::RtScene& scene, std::span<const ddgi::DdgiVolume* const> volumes,
                                    const engine::render::CameraRays& camera, int width, int height,
                                    const ddgi::DdgiRenderSettings& settings) override {
    return ddgi::render_ddgi_gi_batched(scene, volumes, camera, width, height, settings, tracer_, *this);
  }
  [[nodiscard]] const char* name() const override { return name_.c_str(); }
  engine::gpu::GpuTraffic take_traffic() override {
    const engine::gpu::GpuTraffic now = ctx_->traffic(), since = now - traffic_taken_;
    traffic_taken_ = now;
    return since;
  }

 private:
  std::shared_ptr<engine::gpu::VulkanContext> ctx_;
  engine::gpu::GpuTraffic traffic_taken_;
  engine::gpu::GpuRayTracer tracer_;
  VulkanDdgiBlend blend_;
  VulkanProbeShading shading_;
  VulkanDdgiIrradiance irradiance_{*ctx_};
  std::string name_;
};

// The backend --backend NAME asks for: the CPU's for "cpu"; for "vulkan" the
// device's (on `host`, a device the caller made, e.g. the game window's, or
// else the device named: empty = ENGINE_GPU_DEVICE, then the ranked
// default), or the CPU's with the reason no device could run it.
inline ddgi::DdgiBackend make_ddgi_backend(const std::string& backend, const std::string& device,
                                           std::shared_ptr<engine::gpu::VulkanContext> host = nullptr) {
  ddgi::DdgiBackend b;
  if (backend != "vulkan") return b;
  engine::gpu::GpuOptions options;
  options.device = device;
  std::shared_ptr<engine::gpu::VulkanContext> ctx = std::move(host);
  try {
    if (!ctx) ctx = engine::gpu::VulkanContext::create(options, &b.fallback_why);
  } catch (const std::exception& e) {
    b.fallback_why = e.what();
  }
  if (!ctx) {
    b.fallback = probes::BackendFallback::NoDevice;
    return b;
  }
  if (std::string missing; !VulkanProbeShading::supported(*ctx, &missing)) {
    b.fallback = probes::BackendFallback::MissingCapability;
    b.fallback_why = missing;
    return b;
  }
  try {
    b.kernels = std::make_shared<VulkanDdgiKernels>(std::move(ctx));
    b.fallback_why.clear();
  } catch (const std::exception& e) {  // a kernel the device cannot build
    b.fallback = probes::BackendFallback::KernelBuildFailed;
    b.fallback_why = e.what();
  }
  return b;
}

}  // namespace transgi::gpu
