#pragma once
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

#include "engine/ecs/entity.h"

namespace engine::rt {

struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  // need not be unit length; t is in its units
  float tmin = 0.0f;
  float tmax = std::numeric_limits<float>::infinity();
};

// What a closest-hit query found. Barycentrics follow Embree: the point is
// (1 - u - v) p0 + u p1 + v p2 for triangle (p0, p1, p2).
struct Hit {
  ecs::Entity entity;
  std::uint32_t mesh = 0;       // SceneAssets::meshes index
  std::uint32_t primitive = 0;  // triangle index in the mesh
  glm::vec2 barycentric{0.0f};
  float t = std::numeric_limits<float>::infinity();
  // The RtScene instance that was hit, so consumers index its record instead
  // of hashing `entity` once per hit (RtScene::instance_of(const Hit&)).
  // kUnknownInstance for hits made by hand.
  static constexpr std::uint32_t kUnknownInstance = 0xffffffffu;
  std::uint32_t instance = kUnknownInstance;
};

// Offsets a ray origin off a surface along its geometric normal, scaled to
// the floating-point precision of the position (Waechter and Binder 2019,
// Ray Tracing Gems ch. 6), so spawned rays do not re-hit their surface.
// scale: the scene's size where it is under a metre (RtScene::offset_scale).
// Their fixed offset near the origin (1/65536 within 1/32 of it) suits
// scenes of metres; in a scene of millimetres it is the thickness of a wall,
// and rays started beyond walls (a Cornell box scaled by 1e-3 lost half its
// GI), so it shrinks with the scene.
glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& geometric_normal, float scale = 1.0f);

inline bool is_finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace engine::rt
