#pragma once
// Every light a frame can sample: emissive triangles (area lights), punctual
// lights and the environment, with the pdfs MIS needs. Built from the
// RtScene mirror and the world's lights; rebuilt when those change.
//
// Light selection picks one group with equal probability among the groups
// present (environment, area lights, punctual lights), then a triangle by
// emitted power, a punctual light uniformly, or a direction from the
// environment's own importance distribution.
#include <optional>
#include <unordered_map>
#include <vector>

#include "engine/ecs/world.h"
#include "engine/math/distribution.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"

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
  // env may be null. Punctual lights come from the world.
  LightSet(const rt::RtScene& scene, std::vector<PunctualInstance> punctual, const scene::Environment* env);

  // Samples one light as seen from point p (u3: selection, u: position/direction).
  bool sample(const glm::vec3& p, float u_select, glm::vec2 u, LightSample& out) const;
  // Solid-angle pdf that sample() would produce `dir` towards an emissive
  // triangle hit at distance `dist` with light normal `light_n` (from p).
  [[nodiscard]] float pdf_area_light(ecs::Entity entity, std::uint32_t primitive, const glm::vec3& dir, float dist,
                                     const glm::vec3& light_normal) const;
  [[nodiscard]] float pdf_environment(const glm::vec3& dir) const;

  [[nodiscard]] const scene::Environment* environment() const { return env_; }
  [[nodiscard]] std::size_t emissive_triangle_count() const { return triangles_.size(); }
  [[nodiscard]] std::size_t punctual_count() const { return punctual_.size(); }
  [[nodiscard]] const std::vector<PunctualInstance>& punctual_lights() const { return punctual_; }
  [[nodiscard]] bool empty() const { return groups_ == 0; }

 private:
  float group_probability() const { return groups_ > 0 ? 1.0f / static_cast<float>(groups_) : 0.0f; }

  std::vector<EmissiveTriangle> triangles_;
  math::Distribution1D triangle_distribution_;
  std::unordered_map<std::uint64_t, std::uint32_t> triangle_of_;  // (entity index, prim) -> triangles_ index
  std::vector<PunctualInstance> punctual_;
  const scene::SceneAssets* assets_ = nullptr;
  const scene::Environment* env_ = nullptr;
  int groups_ = 0;
};

// A punctual light placed by its world transform; nullopt when it is off
// (disabled or zero intensity).
std::optional<PunctualInstance> punctual_instance(const scene::PunctualLight& light, const transform::Similarity& to_world);

// Collects the world's enabled punctual lights.
std::vector<PunctualInstance> gather_punctual_lights(ecs::World& world);

}  // namespace engine::render
