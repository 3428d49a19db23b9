#pragma once
// DDGI's stages on the CPU (ddgi::DdgiKernels): Embree's rays, the job
// system's threads. The oracle the Vulkan backend is tested against, and
// the backend every volume holds unless a device is chosen.
#include "ddgi/ddgi_kernels.h"

namespace transgi::ddgi {

class CpuDdgiKernels final : public DdgiKernels {
 public:
  void shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                        std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                        std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                        const ProbeRayBounce& bounce, const ProbeRayConsumer& consume) override;
  engine::rt::RayBatchTracer* tracer() override { return nullptr; }
  void blend(std::vector<OctahedralMap<glm::vec3>>& irradiance, std::vector<OctahedralMap<glm::vec2>>& distance,
             const std::vector<std::vector<RayRecord>>& records, const DdgiSettings& settings, float hysteresis,
             bool clamp_brightness, float max_distance) override;
  void irradiance(std::span<const DdgiVolume* const> volumes, std::span<const glm::vec3> positions,
                  std::span<const glm::vec3> normals, std::span<const glm::vec3> view_dirs,
                  std::span<glm::mat2x3> out) override;
  engine::image::ImageRGB render_gi(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                    const engine::render::CameraRays& camera, int width, int height,
                                    const DdgiRenderSettings& settings) override;
  [[nodiscard]] const char* name() const override { return "cpu"; }
};

// The one CPU backend, shared by every volume that is given no other.
std::shared_ptr<DdgiKernels> cpu_ddgi_kernels();

}  // namespace transgi::ddgi
