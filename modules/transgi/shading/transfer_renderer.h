#pragma once
// Object-scale TransGI shading (the paper's Fig. 7 setting): every visible
// point's transfer, decoded by the network (or integrated as ground truth),
// dotted with SH light rotated into the object's frame. Pixels that see no
// object show the environment, as in the reference.
#include <array>
#include <functional>
#include <memory>
#include <unordered_map>

#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "engine/rt/rt_scene.h"
#include "model/transfer_model.h"
#include "shading/sh_light.h"

namespace transgi::shading {

enum class TransferSource {
  Network,      // decoded by the model (TransGI)
  GroundTruth,  // integrated per pixel (measures SH truncation alone)
};

struct TransferRenderSettings {
  int spp = 4;                 // G-buffer samples per pixel (filtered like the reference)
  // Which entities carry baked transfer (a LatentMesh). Null = every entity.
  // The others skip inference and are shaded diffusely from the same SH
  // light: diffuse albedo / pi x irradiance.
  std::function<bool(engine::ecs::Entity)> has_transfer = nullptr;
  int ground_truth_rays = 2048;
  std::uint64_t seed = 0;
  float filter_width = 1.5f;
};

struct TransferRenderTimings {
  double gbuffer_ms = 0, inputs_ms = 0, inference_ms = 0, shading_ms = 0;
};

struct TransferRenderResult {
  engine::image::ImageRGB image;
  // Per-pixel transfer coefficients t[k] (luminance-weighted over RGB) for
  // k = (0,0), (1,0), (2,0), averaged over the pixel's samples (Fig. 10).
  std::array<engine::image::ImageRGB, 3> coefficient_maps;
  std::size_t shaded_samples = 0;
  std::size_t inferred_samples = 0;  // of which had transfer decoded (the rest: diffuse fallback)
  TransferRenderTimings timings;
  double light_ms = 0;  // fetching the SH light per shaded sample (probe interpolation)
};

// World-space SH light arriving at a shading point (position, normal).
using LightAt = std::function<void(const glm::vec3& position, const glm::vec3& normal, float* out75)>;

TransferRenderResult render_transfer(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                                     const model::TransferModel& model, const engine::render::CameraRays& camera,
                                     int width, int height, const LightAt& light_at,
                                     const engine::scene::Environment* background, TransferSource source,
                                     const TransferRenderSettings& settings);

// The same light everywhere (object scale: an environment projected to SH).
LightAt constant_light(const ShRgb& world_light);

}  // namespace transgi::shading
