#pragma once
// Lat-long environment light in Mitsuba 0.5's convention (see
// docs/scene-format.md): for a world direction d, l = normalize(inverse(M) d),
// u = atan2(l.x, -l.z) / (2 pi) wrapped to [0, 1), v = acos(l.y) / pi with
// v = 0 the top row. Radiance = strength * pixel. Importance sampled by
// pixel luminance times sin(theta).
#include <algorithm>
#include <cmath>
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
  [[nodiscard]] const math::AliasDistribution2D& distribution() const { return distribution_; }

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
  math::AliasDistribution2D distribution_;
};

// A constant-radiance environment (for furnace tests) is just a 1x1 map.
Environment uniform_environment(glm::vec3 radiance);

// The integration rule that projections of a map share (its SH over the
// sphere, or per cell of directions): lookups are nearest-texel, so each
// texel is constant radiance over its patch of the sphere, and each patch
// is visited in sub-cells with their exact solid angle, fine enough that
// even a tiny map integrates exactly enough (at least 1024 x 512 over the
// sphere). fn(x, y, world_direction, solid_angle) for every sub-cell of
// texel rows [y0, y1); the texel's radiance is strength x image.at(x, y).
template <class Fn>
void for_each_patch_sample(const Environment& env, int y0, int y1, Fn&& fn) {
  const image::ImageRGB& img = env.image();
  const int w = img.width, h = img.height;
  const int sub_x = std::max(1, (1024 + w - 1) / w), sub_y = std::max(1, (512 + h - 1) / h);
  const double pi = 3.14159265358979323846;
  for (int y = y0; y < y1; ++y)
    for (int x = 0; x < w; ++x)
      for (int sy = 0; sy < sub_y; ++sy) {
        const double v0 = (y + static_cast<double>(sy) / sub_y) / h, v1 = (y + (sy + 1.0) / sub_y) / h;
        const double d_omega = (2.0 * pi / (static_cast<double>(w) * sub_x)) * (std::cos(pi * v0) - std::cos(pi * v1));
        const double v = 0.5 * (v0 + v1);
        for (int sx = 0; sx < sub_x; ++sx) {
          const double u = (x + (sx + 0.5) / sub_x) / w;
          const glm::vec3 local = Environment::uv_to_direction({static_cast<float>(u), static_cast<float>(v)});
          fn(x, y, glm::normalize(env.to_world(local)), d_omega);
        }
      }
}

}  // namespace engine::scene
