#pragma once
// Every light a frame can sample: emissive triangles (area lights), punctual
// lights and the environment, with the pdfs MIS needs. Built from the
// RtScene mirror and the world's lights; rebuilt when those change.
//
// Light selection picks one group with equal probability among the groups
// present (environment, area lights, punctual lights), then a triangle by
// emitted power, a punctual light uniformly, or a direction from the
// environment's own importance distribution.
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "engine/ecs/world.h"
#include "engine/math/distribution.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/scene/sun_extraction.h"

namespace engine::render {

struct EmissiveTriangle {
  glm::vec3 p0, p1, p2;
  glm::vec2 uv0{0.0f}, uv1{0.0f}, uv2{0.0f};
  std::uint32_t material = 0;
  glm::vec3 emission;  // factor * strength; the emissive texture modulates it per point
  float area;
};

struct PunctualInstance {
  scene::PunctualLight light;
  glm::vec3 position;
  glm::vec3 direction;  // the way the light shines (its local -Z in world space)
  // Directional only: half-angle of the source's disk (a sun split out of
  // the environment); 0 = a delta light. Samples spread over the disk, so
  // shadows get the penumbra the disk gives.
  float angular_radius = 0.0f;
};

struct LightSample {
  glm::vec3 radiance{0.0f};  // Li arriving at the shading point (already / d^2 for punctual)
  glm::vec3 direction{0.0f}; // unit, from the shading point to the light
  float distance = 0.0f;     // to the light (inf for environment / directional)
  float pdf = 0.0f;          // solid-angle pdf including selection; 0 for delta lights
  bool delta = false;
};

class LightSet {
 public:
  LightSet() = default;
  // env may be null. Punctual lights come from the world. With a sun split
  // of env, the split's sun becomes one more directional light and the
  // residual map replaces env for lighting (env stays the background).
  LightSet(const rt::RtScene& scene, std::vector<PunctualInstance> punctual, const scene::Environment* env,
           std::shared_ptr<const scene::SunSplit> sun_split = nullptr);

  // Samples one light as seen from point p (u3: selection, u: position/direction).
  bool sample(const glm::vec3& p, float u_select, glm::vec2 u, LightSample& out) const;
  // Samples the area lights alone (a triangle by emitted power, then a point
  // on it uniformly), as seen from p: out.pdf counts no group selection.
  // False where there are none or the point is degenerate.
  bool sample_area_light(const glm::vec3& p, glm::vec2 u, LightSample& out) const;
  // Solid-angle pdf that sample() would produce `dir` towards an emissive
  // triangle hit at distance `dist` with light normal `light_n` (from p).
  [[nodiscard]] float pdf_area_light(ecs::Entity entity, std::uint32_t primitive, const glm::vec3& dir, float dist,
                                     const glm::vec3& light_normal) const;
  [[nodiscard]] float pdf_environment(const glm::vec3& dir) const;
  // Punctual light i as seen from p, not divided by any selection
  // probability (renderers that shade every light once). u picks a point
  // on a sun's disk; delta lights ignore it.
  bool sample_punctual(std::size_t i, const glm::vec3& p, glm::vec2 u, LightSample& out) const;

  // The environment that lights the scene (the residual when the sun is split out).
  [[nodiscard]] const scene::Environment* environment() const { return env_; }
  // The environment as the camera sees it (with its sun disk).
  [[nodiscard]] const scene::Environment* background() const { return background_; }
  // The sun taken out of the environment, as a punctual light (index into punctual_lights()), or -1.
  [[nodiscard]] int split_sun_index() const { return split_sun_index_; }
  [[nodiscard]] std::size_t emissive_triangle_count() const { return triangles_.size(); }
  [[nodiscard]] std::size_t punctual_count() const { return punctual_.size(); }
  [[nodiscard]] const std::vector<PunctualInstance>& punctual_lights() const { return punctual_; }
  [[nodiscard]] bool empty() const { return groups_ == 0; }
  // What sample() draws from, for kernels that sample the same lights.
  [[nodiscard]] const std::vector<EmissiveTriangle>& emissive_triangles() const { return triangles_; }
  [[nodiscard]] const math::Distribution1D& triangle_distribution() const { return triangle_distribution_; }
  [[nodiscard]] int groups() const { return groups_; }

 private:
  float group_probability() const { return groups_ > 0 ? 1.0f / static_cast<float>(groups_) : 0.0f; }
  // sample_area_light with the group's selection pdf folded in.
  bool sample_area_light(const glm::vec3& p, glm::vec2 u, float group_pdf, LightSample& out) const;

  std::vector<EmissiveTriangle> triangles_;
  math::Distribution1D triangle_distribution_;
  std::unordered_map<std::uint64_t, std::uint32_t> triangle_of_;  // (entity index, prim) -> triangles_ index
  std::vector<PunctualInstance> punctual_;
  const scene::SceneAssets* assets_ = nullptr;
  const scene::Environment* env_ = nullptr;
  const scene::Environment* background_ = nullptr;
  std::shared_ptr<const scene::SunSplit> sun_split_;  // owns the residual env_ points to
  int split_sun_index_ = -1;
  int groups_ = 0;
};

// A punctual light placed by its world transform; nullopt when it is off
// (disabled or zero intensity).
std::optional<PunctualInstance> punctual_instance(const scene::PunctualLight& light, const transform::Similarity& to_world);

// Collects the world's enabled punctual lights.
std::vector<PunctualInstance> gather_punctual_lights(ecs::World& world);

}  // namespace engine::render
