#include "ddgi/cpu_ddgi_kernels.h"


#include "ddgi/ddgi_renderer.h"
#include "engine/jobs/parallel_for.h"

namespace transgi::ddgi {

void CpuDdgiKernels::shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                      std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                                      std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                                      const ProbeRayBounce& bounce, const ProbeRayConsumer& consume) {
  probes::trace_listed_probe_rays(scene, lights, origins, probe_ids, directions, seed, sample, bounce, consume);
}

void CpuDdgiKernels::blend(std::vector<OctahedralMap<glm::vec3>>& irradiance, std::vector<OctahedralMap<glm::vec2>>& distance,
                           const std::vector<std::vector<RayRecord>>& records, const DdgiSettings& settings, float hysteresis,
                           bool clamp_brightness, float max_distance) {
  engine::jobs::parallel_for(0, static_cast<int>(records.size()), 1, [&](int b, int e) {
    for (int q = b; q < e; ++q) {
      const auto i = static_cast<std::size_t>(q);
      if (records[i].empty()) continue;
      blend_irradiance(irradiance[i], records[i], settings, hysteresis, clamp_brightness);
      blend_distance(distance[i], records[i], settings, max_distance, hysteresis);
    }
  });
}

void CpuDdgiKernels::irradiance(std::span<const DdgiVolume* const> volumes, std::span<const glm::vec3> positions,
                                std::span<const glm::vec3> normals, std::span<const glm::vec3> view_dirs,
                                std::span<glm::mat2x3> out) {
  engine::jobs::parallel_for<std::size_t>(0, positions.size(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) out[k] = irradiance_and_emitted_from(volumes, positions[k], normals[k], view_dirs[k]);
  });
}

engine::image::ImageRGB CpuDdgiKernels::render_gi(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                                  const engine::render::CameraRays& camera, int width, int height,
                                                  const DdgiRenderSettings& settings) {
  return render_ddgi_gi(scene, volumes, camera, width, height, settings);
}

std::shared_ptr<DdgiKernels> cpu_ddgi_kernels() {
  static const std::shared_ptr<DdgiKernels> kernels = std::make_shared<CpuDdgiKernels>();
  return kernels;
}

}  // namespace transgi::ddgi
