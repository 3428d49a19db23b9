#pragma once
// DDGI's indirect diffuse at every pixel: a filtered primary ray per sample
// (as TransGI's G-buffer), then diffuse albedo / pi x the volume's irradiance
// at the hit. Glossy indirect light is not DDGI's to give.
#include "ddgi/ddgi_volume.h"
#include "engine/image/image.h"
#include "engine/render/camera_rays.h"

namespace transgi::ddgi {

struct DdgiRenderSettings {
  int spp = 1;
  std::uint64_t seed = 0;
  float filter_width = 1.5f;
};

engine::image::ImageRGB render_ddgi_gi(const engine::rt::RtScene& scene, const DdgiVolume& volume,
                                       const engine::render::CameraRays& camera, int width, int height,
                                       const DdgiRenderSettings& settings);

}  // namespace transgi::ddgi
