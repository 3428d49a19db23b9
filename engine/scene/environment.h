#pragma once
// Lat-long environment light in Mitsuba 0.5's convention (see
// docs/scene-format.md): for a world direction d, l = normalize(inverse(M) d),
// u = atan2(l.x, -l.z) / (2 pi) wrapped to [0, 1), v = acos(l.y) / pi with
// v = 0 the top row. Radiance = strength * pixel. Importance sampled by
// pixel luminance times sin(theta).
#include <memory>

#include <glm/glm.hpp>

#include "engine/image/image.h"
#include "engine/math/distribution.h"

namespace engine::scene {

class Environment {
 public:
  Environment() = default;
  // matrix: the map's local-to-world transform (column-major, glTF frame).
  Environment(image::ImageRGB image, float strength, const glm::mat4& matrix);

  // Radiance arriving from world direction d (d points from the scene to the sky).
  [[nodiscard]] glm::vec3 radiance(const glm::vec3& world_dir) const;
  // Samples a world direction with probability proportional to the map's
  // luminance; pdf is per solid angle. Returns radiance.
  glm::vec3 sample(glm::vec2 u, glm::vec3* world_dir, float* pdf) const;
  [[nodiscard]] float pdf(const glm::vec3& world_dir) const;

  [[nodiscard]] const image::ImageRGB& image() const { return image_; }
  // Map-local direction to world (the matrix's rotation).
  [[nodiscard]] glm::vec3 to_world(const glm::vec3& local) const { return to_world_ * local; }
  [[nodiscard]] float strength() const { return strength_; }
  // Run-time sky control (a day-night cycle): turn the map about world +Y
  // by `radians` from its loaded orientation, and scale its brightness. Both
  // are cheap (the sampling distribution lives in map space). Whoever calls
  // them bumps SceneAssets::edit_version so light caches rebuild.
  void set_yaw(float radians);
  [[nodiscard]] float yaw() const { return yaw_; }
  void set_strength(float strength) { strength_ = strength; }
  [[nodiscard]] bool valid() const { return !image_.empty(); }
  // The map's frame and importance distribution, for kernels that sample it.
  [[nodiscard]] const glm::mat3& to_world_matrix() const { return to_world_; }
  [[nodiscard]] const glm::mat3& to_local_matrix() const { return to_local_; }
  [[nodiscard]] const math::Distribution2D& distribution() const { return distribution_; }

  // Map-local direction <-> (u, v).
  static glm::vec2 direction_to_uv(const glm::vec3& local);
  static glm::vec3 uv_to_direction(glm::vec2 uv);

 private:
  image::ImageRGB image_;
  float strength_ = 1.0f;
  glm::mat3 to_world_{1.0f};
  glm::mat3 to_local_{1.0f};
  glm::mat3 loaded_to_world_{1.0f};
  float yaw_ = 0.0f;
  math::Distribution2D distribution_;
};

// A constant-radiance environment (for furnace tests) is just a 1x1 map.
Environment uniform_environment(glm::vec3 radiance);

}  // namespace engine::scene
