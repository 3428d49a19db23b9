#pragma once
// One G-buffer sample: what a camera ray hit, in the terms the transfer
// shading needs (object-space normal and view for the network, world-space
// position and normal for the probes, depth for edge-aware upsampling).
// Shared by the batched transfer renderer and the real-time GI path.
#include "engine/material/brdf.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/environment.h"

namespace transgi::shading {

struct GSample {
  bool hit = false;
  engine::ecs::Entity entity;
  std::uint32_t mesh = 0, triangle = 0;
  glm::vec2 bary{0.0f};
  glm::vec3 normal_obj{0.0f}, wo_obj{0.0f}, albedo{0.0f}, diffuse{0.0f}, background{0.0f};
  glm::vec3 position{0.0f}, normal_world{0.0f};
  // For direct light: the full material, what the surface emits, the world
  // geometric normal facing the viewer (shadow-ray offsets) and the unit
  // direction back to the camera.
  engine::material::BrdfParams brdf;
  glm::vec3 emission{0.0f}, geometric_normal{0.0f}, wo_world{0.0f};
  float depth = 0.0f;  // distance along the camera ray
};

// Traces `ray` and fills the sample; a miss records the background's
// radiance (none if background is null). Normals face the viewer (surfaces
// are two-sided). spread: the ray cone's spread angle (CameraRays::
// pixel_spread()); textures are read at the mip level of the cone's
// footprint, as a rasteriser would, so the albedo fed to the network and to
// shading is a pixel's average, not one texel. 0 = point samples.
GSample trace_gsample(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                      const engine::rt::Ray& ray, const engine::scene::Environment* background, float spread = 0);
// The sample for a hit found elsewhere (a packet query); `hit` may be null
// for a miss.
GSample make_gsample(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                     const engine::rt::Ray& ray, const engine::rt::Hit* hit, const engine::scene::Environment* background,
                     float spread = 0);
// The same, written over `out` in place (every field; a G-buffer of 200-byte
// samples need not copy each one).
void make_gsample(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets, const engine::rt::Ray& ray,
                  const engine::rt::Hit* hit, const engine::scene::Environment* background, float spread, GSample& out);

// The sample's fields that follow from the hit and its material alone (the
// ids, the material read at the hit's texture footprint, the depth), for
// make_gsample and make_gsamples, which compute the geometry themselves;
// ng_dot_wo: the world geometric normal's cosine with the direction back to
// the camera (the footprint stretches at grazing angles).
void set_gsample_material(const engine::scene::SceneAssets& assets, const engine::rt::Hit& hit, const engine::scene::MeshAsset& mesh,
                          float instance_scale, float spread, float ng_dot_wo, GSample& out);

// The most samples make_gsamples makes at once: a 4 x 4 camera tile.
inline constexpr int kGSampleTile = 16;
// Per-pixel arrays a G-buffer keeps beside its samples (realtime_gi.h's
// GBuffer says what each holds), written by make_gsamples for lane i at
// index pixel[i] from the values it computed, instead of read back from the
// samples it has just stored.
struct GSampleSideArrays {
  const std::size_t* pixel = nullptr;
  glm::vec4* guide = nullptr;             // world normal, depth (0: a miss)
  glm::vec3* position = nullptr;          // 0 for a miss
  glm::vec3* albedo = nullptr;            // the base colour, 0 for a miss
  float* metal_roughness = nullptr;       // roughness where metallic >= 0.5, else infinity
  float* dielectric_roughness = nullptr;  // roughness of a non-metal with specular > 0, else infinity
  engine::ecs::Entity* entity = nullptr;  // null for a miss
};
// make_gsample for n <= kGSampleTile rays at once (no background: a miss is
// GSample{}), written to *out[i], and to `sides` where given: the same
// samples, bit for bit, faster (the arithmetic runs across the rays in SIMD
// lanes; gbuffer_tile.cpp).
void make_gsamples(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets, const engine::rt::Ray* rays,
                   const engine::rt::Hit* hits, const bool* found, int n, float spread, GSample* const* out,
                   const GSampleSideArrays* sides = nullptr);

}  // namespace transgi::shading
