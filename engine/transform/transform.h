#pragma once
// Rigid transforms with uniform scale (similarities). Uniform scale keeps the
// composition of two similarities a similarity, so world transforms stay in
// (translation, rotation, scale) form with no shear, and normals transform by
// the rotation alone.
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/ecs/entity.h"

namespace engine::transform {

struct Similarity {
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // w, x, y, z
  float scale = 1.0f;

  [[nodiscard]] glm::vec3 apply_point(const glm::vec3& p) const { return translation + rotation * (scale * p); }
  [[nodiscard]] glm::vec3 apply_vector(const glm::vec3& v) const { return rotation * (scale * v); }
  [[nodiscard]] glm::vec3 apply_direction(const glm::vec3& d) const { return rotation * d; }

  [[nodiscard]] glm::mat4 matrix() const;
  [[nodiscard]] Similarity inverse() const;
  // (this * child) applies child first, then this.
  [[nodiscard]] Similarity operator*(const Similarity& child) const;

  friend bool operator==(const Similarity& a, const Similarity& b) {
    return a.translation == b.translation && a.rotation == b.rotation && a.scale == b.scale;
  }
};

// Local transform, relative to the Parent entity (or the world if none).
struct Transform : Similarity {
  static Transform from_translation(const glm::vec3& t) {
    Transform x;
    x.translation = t;
    return x;
  }
};

// Object-to-world transform, written only by the transform propagation
// system in PostUpdate.
struct WorldTransform : Similarity {};

// The entity this one is attached to.
struct Parent {
  ecs::Entity entity;
};

}  // namespace engine::transform
