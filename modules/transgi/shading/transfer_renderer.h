#pragma once
// Object-scale TransGI shading (the paper's Fig. 7 setting): every visible
// point's transfer, decoded by the network (or integrated as ground truth),
// dotted with SH light rotated into the object's frame. Pixels that see no
// object show the environment, as in the reference.
#include <array>
#include <functional>
#include <optional>
#include <memory>
#include <unordered_map>

#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "engine/math/rng.h"
#include "engine/render/light_set.h"
#include "engine/render/surface.h"
#include "engine/rt/rt_scene.h"
#include "model/transfer_model.h"
#include "shading/gbuffer.h"
#include "shading/near_field.h"
#include "shading/sh_light.h"

namespace transgi::shading {

enum class TransferSource {
  Network,      // decoded by the model (TransGI)
  GroundTruth,  // integrated per pixel (measures SH truncation alone)
};

// Near-mirrors (metallic, roughness at most `max_roughness`; negative = off)
// get one reflection ray instead of SH transfer, which cannot hold a mirror
// (the paper's limitation; engines trace reflections): the hit's radiance is
// its diffuse albedo / pi times the probe irradiance there plus its direct
// light (the quality path: `light_samples` next-event samples; the real-time
// path: the probes' direct SH and a shadow ray per punctual light), weighted
// by the mirror's Fresnel. Used by both paths. Higher max_roughness = more
// surfaces reflect sharply, at the cost of one ray per such pixel and the
// glossy blur lost.
struct MirrorRay {
  float max_roughness = 0.05f;
  // The quality path only (the real-time path lights its reflections' hits
  // with the probes' direct SH and one shadow ray per punctual light).
  // Higher = less grain in what a mirror shows (a light seen through a
  // window is found by few samples), at the cost of shadow rays per mirror
  // pixel.
  int light_samples = 16;
  // The real-time path only: metals rougher than max_roughness up to this
  // reflect by one GGX-sampled ray a pixel, a different one at each phase
  // of the antialiasing's jitter, which averages them (a still view shows
  // the mean of one cycle's 16). SH-4 transfer cannot hold a glossy metal's
  // reflections (the gold sphere was a matte orange ball). Higher = more
  // metals with real reflections, at the cost of a ray and its light samples
  // per such pixel, and noise in motion. Below max_roughness = off.
  float glossy_max_roughness = 0.5f;
  // The real-time path only: non-metals with a specular layer (varnish,
  // plastic, ceramic) up to this roughness take their specular reflection
  // from GGX-sampled rays, one per 2x2 pixels, filtered, and their diffuse
  // light from the probes' irradiance instead of the network's SH-4
  // transfer, which blurs a varnished floor's reflection of a window into a
  // grey haze over the whole floor. 0.4 is where Unreal's Lumen stops
  // tracing reflections by default; rougher lobes are broad enough for the
  // transfer. Higher = more surfaces with traced reflections, at the cost
  // of a ray per four such pixels and the network's contact detail in their
  // diffuse light. Below 0 = off.
  float dielectric_max_roughness = 0.4f;
  bool operator==(const MirrorRay&) const = default;
};

// World-space SH light arriving at a shading point (position, normal).
using LightAt = std::function<void(const glm::vec3& position, const glm::vec3& normal, float* out75)>;

struct TransferRenderSettings {
  int spp = 4;                 // G-buffer samples per pixel (filtered like the reference)
  // Which entities carry baked transfer (a LatentMesh). Null = every entity.
  // The others skip inference and are shaded diffusely from the same SH
  // light: diffuse albedo / pi x irradiance.
  std::function<bool(engine::ecs::Entity)> has_transfer = nullptr;
  int ground_truth_rays = 2048;
  // Textures read at the mip level of each primary ray's cone (ray cones), as
  // rasterisers do. Off = point samples, which alias at one sample per pixel.
  bool texture_filtering = true;
  // ... that many mip levels finer: a pixel's samples and the still view's
  // temporal window already average its area under the pixel filter, and
  // the mip's own filter on top of that blurred textures (as under TAA:
  // TemporalAaSettings::texture_lod_bias). Lower = sharper, at the cost of
  // aliasing where few samples average a pixel.
  float texture_lod_bias = -1.0f;
  std::uint64_t seed = 0;
  // The G-buffer's sub-pixel positions: frame `frame_index`'s spp points of
  // one R2 sequence per pixel, shifted by a per-pixel offset drawn from
  // `pattern_seed`. Consecutive frames take the sequence's next points, so
  // a still view's temporal window (TransGISettings::temporal_window) is
  // stratified over the pixel instead of independent random points (those
  // left thin frames grainy after 16 frames).
  std::uint64_t pattern_seed = 0;
  std::uint64_t frame_index = 0;
  float filter_width = 1.5f;
  MirrorRay mirror{};
  const engine::render::LightSet* lights = nullptr;  // for the mirror ray's and near field's next-event samples (null: none)
  // Contact light by short rays (near_field.h); read where probe_spacing_at
  // is set: the smallest probe spacing of the grid that lights a point.
  NearFieldRays near_field{};
  std::function<float(const glm::vec3&)> probe_spacing_at = nullptr;
};

// A reflection of the sample's specular lobe: its direction and weight
// (f cos / pdf) with the lobe's Fresnel (a metal's base colour, else the
// dielectric layer's 0.04 specular_color x specular). `mirror`: the mirror
// direction (weight: Fresnel at the view angle); else one GGX visible-normal
// sample drawn with u. False when there is none (a grazing view).
bool sample_reflection(const GSample& sample, bool mirror, glm::vec2 u, glm::vec3& wi, glm::vec3& weight);
// What one reflection ray brings back, split as the frame's passes are:
// `direct` is the sky or emitter it sees (light reflected once), `gi` what
// its hit reflects diffusely.
struct ReflectedLight {
  glm::vec3 direct{0.0f}, gi{0.0f};
};
// The irradiance at a reflection ray's hit.
using HitIrradiance = std::function<glm::vec3(const engine::render::Surface& hit)>;
// Traces from the sample along wi: a miss sees `sky` (the lighting
// environment; null = black), an emitter its emission, a hit with a diffuse
// lobe reflects its directional albedo towards the sample / pi x
// irradiance(hit) (reflected_gi). Not weighted.
ReflectedLight reflected_light(const engine::rt::RtScene& scene, const GSample& sample, const glm::vec3& wi,
                               const engine::scene::Environment* sky, const HitIrradiance& irradiance);
// reflected_light in parts, for callers that trace many rays at once and
// light their hits in a batch (realtime_reflections.cpp). The ray from the
// sample along wi; false where wi points below its surface (no light).
bool reflection_ray(const engine::rt::RtScene& scene, const GSample& sample, const glm::vec3& wi, engine::rt::Ray& ray);
// What the traced ray brings back when that does not need the hit's
// irradiance (a miss: the sky; an emitter; a black surface); else
// std::nullopt, and reflected_gi(hit, irradiance at it) is its light.
std::optional<ReflectedLight> reflected_without_irradiance(const engine::render::Surface* hit, const glm::vec3& wi,
                                                           const engine::scene::Environment* sky);
// The light a reflection ray's hit sends back along the ray (wi: the ray's
// direction) from its irradiance taken as arriving evenly: its whole
// directional albedo towards the ray's origin (diffuse and specular lobes,
// engine::material::directional_albedo) / pi. A varnished wall or table
// seen in a floor reflects the room with its specular layer too; the
// diffuse albedo alone left that light out.
glm::vec3 reflected_gi(const engine::render::Surface& hit, const glm::vec3& wi, const glm::vec3& irradiance);
// The quality path's mirror: the light leaving a point of a near-mirror
// towards the viewer, its Fresnel times what the reflection ray finds
// (reflected_light above, no sky), its hit lit by the probes (light_at) and
// mirror.light_samples samples of `lights`. Emitters seen in the mirror are
// `direct`, as in the reference's passes. (The real-time frame traces its
// reflections in shading/realtime_gi.cpp, its hits lit by the probes alone.)
ReflectedLight shade_mirror(const engine::rt::RtScene& scene, const GSample& sample, const LightAt& light_at,
                            const engine::render::LightSet* lights, const MirrorRay& mirror, engine::math::Pcg32& rng);
// The same for a glossy surface (alpha = roughness^2), by one ray sampled
// from the GGX distribution of visible normals with u (sample_reflection):
// its Fresnel and shadowing, F(wo.h) G1(wi), times what it finds.
// mirror_direction: the mirror's ray instead (shade_mirror).
ReflectedLight shade_glossy(const engine::rt::RtScene& scene, const GSample& sample, const LightAt& light_at,
                            const engine::render::LightSet* lights, const MirrorRay& mirror, glm::vec2 u,
                            engine::math::Pcg32& rng, bool mirror_direction = false);
// Whether a sample takes the mirror path.
bool is_mirror(const engine::material::BrdfParams& brdf, const MirrorRay& mirror);

struct TransferRenderTimings {
  double gbuffer_ms = 0, inputs_ms = 0, inference_ms = 0, shading_ms = 0;
};

struct TransferRenderResult {
  engine::image::ImageRGB image;
  // Per-pixel transfer coefficients t[k] (luminance-weighted over RGB) for
  // k = (0,0), (1,0), (2,0), averaged over the pixel's samples (Fig. 10).
  std::array<engine::image::ImageRGB, 3> coefficient_maps;
  std::size_t shaded_samples = 0;
  std::size_t inferred_samples = 0;  // of which had transfer decoded (the rest: diffuse fallback or mirror)
  std::size_t mirror_samples = 0;    // of which took the mirror path
  TransferRenderTimings timings;
  double light_ms = 0;  // fetching the SH light per shaded sample (probe interpolation)
};


// The G-buffer's sub-pixel position for a pixel's sample `sample` (frame
// index x spp + the sample within the frame), in [0, 1)^2 before the pixel
// filter: point `sample` of the R2 sequence shifted by a per-pixel offset
// drawn from `pattern_seed`.
glm::vec2 gbuffer_subpixel(std::uint64_t pattern_seed, std::size_t pixel, std::uint64_t sample);

TransferRenderResult render_transfer(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                                     const model::TransferModel& model, const engine::render::CameraRays& camera,
                                     int width, int height, const LightAt& light_at,
                                     const engine::scene::Environment* background, TransferSource source,
                                     const TransferRenderSettings& settings);

// The same light everywhere (object scale: an environment projected to SH).
LightAt constant_light(const ShRgb& world_light);

}  // namespace transgi::shading
