#pragma once
// DDGI's indirect diffuse at every pixel: a filtered primary ray per sample
// (as TransGI's G-buffer), then diffuse albedo / pi x the volume's irradiance
// at the hit. Glossy indirect light is not DDGI's to give.
#include <span>

#include "ddgi/ddgi_kernels.h"
#include "ddgi/ddgi_volume.h"
#include "engine/image/image.h"
#include "engine/render/camera_rays.h"

namespace transgi::ddgi {

struct DdgiRenderSettings {
  int spp = 1;
  std::uint64_t seed = 0;
  float filter_width = 1.5f;
};

// Irradiance from several volumes (authored ones, then cascades finest
// first), blended as probes::mix_at says; a volume with no active probe
// around the point hands it to the next one holding it. With one volume,
// exactly its DdgiVolume::irradiance.
glm::vec3 irradiance_from(std::span<const DdgiVolume* const> volumes, const glm::vec3& position, const glm::vec3& normal,
                          const glm::vec3& view_dir);

// With `kernels` (a GPU backend) and a single volume, the primary rays go to
// its tracer and the irradiance lookups to its kernel, each in one batch;
// the surfaces are made on the CPU between the two.
engine::image::ImageRGB render_ddgi_gi(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                       const engine::render::CameraRays& camera, int width, int height,
                                       const DdgiRenderSettings& settings, DdgiKernels* kernels = nullptr);

}  // namespace transgi::ddgi
