#pragma once
// Pinhole camera rays from a scene::Camera and its WorldTransform. Pixel
// (0, 0) is the top-left; the camera looks down its local -Z with +Y up.
#include <optional>

#include "engine/ecs/entity.h"
#include "engine/rt/ray.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"

namespace engine::render {

struct CameraRays {
  CameraRays(const scene::Camera& camera, const transform::Similarity& to_world, int width, int height);
  // film = pixel coordinates with sub-pixel offset, e.g. (x + 0.5, y + 0.5).
  // Inline: the G-buffer calls it once per pixel.
  [[nodiscard]] rt::Ray generate(glm::vec2 film) const {
    const float sx = (2.0f * film.x / static_cast<float>(width_) - 1.0f) * tan_half_x_;
    const float sy = (1.0f - 2.0f * film.y / static_cast<float>(height_)) * tan_half_y_;
    rt::Ray r;
    r.origin = origin_;
    r.direction = glm::normalize(rotation_ * glm::vec3(sx, sy, -1.0f));
    return r;
  }
  // A ray through pixel (x, y) offset by the pixel filter (see below), from
  // two uniform numbers u.
  [[nodiscard]] rt::Ray generate_filtered(int x, int y, glm::vec2 u, float filter_width) const;
  // The film coordinates where world point p appears (generate's inverse:
  // generate(*project(p)) points at p); nullopt behind the camera.
  [[nodiscard]] std::optional<glm::vec2> project(const glm::vec3& p) const {
    const glm::vec3 d = p - origin_;
    // rotation_ is orthonormal: its transpose is its inverse.
    const glm::vec3 local(glm::dot(rotation_[0], d), glm::dot(rotation_[1], d), glm::dot(rotation_[2], d));
    if (!(local.z < 0)) return std::nullopt;
    const float sx = local.x / -local.z, sy = local.y / -local.z;
    return glm::vec2((sx / tan_half_x_ + 1.0f) * 0.5f * static_cast<float>(width_),
                     (1.0f - sy / tan_half_y_) * 0.5f * static_cast<float>(height_));
  }
  // tan of half the field of view, horizontally and vertically: generate()
  // maps film (x, y) to the camera-space direction
  // ((2x / width - 1) tan_half_x, (1 - 2y / height) tan_half_y, -1).
  [[nodiscard]] float tan_half_x() const { return tan_half_x_; }
  [[nodiscard]] float tan_half_y() const { return tan_half_y_; }
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] glm::vec3 position() const { return origin_; }
  [[nodiscard]] const transform::Similarity& to_world() const { return to_world_; }
  // A pixel's angular size at the image centre (radians): the spread of a
  // primary ray's cone, for texture footprints (ray cones).
  [[nodiscard]] float pixel_spread() const { return 2.0f * tan_half_y_ / static_cast<float>(height_); }

 private:
  glm::vec3 origin_;
  transform::Similarity to_world_;
  glm::mat3 rotation_;
  float tan_half_y_, tan_half_x_;
  int width_, height_;
};

// Rays of the camera entity `requested` when it is in `cameras` (a view of
// const Camera and const WorldTransform), else of the first camera there;
// nullopt when the world has none. What every renderer system asks for.
template <class CameraView>
std::optional<CameraRays> camera_rays_for(const CameraView& cameras, ecs::Entity requested, int width, int height) {
  const scene::Camera* camera = nullptr;
  const transform::WorldTransform* to_world = nullptr;
  cameras.each([&](ecs::Entity e, const scene::Camera& c, const transform::WorldTransform& w) {
    if (!camera || e == requested) {
      camera = &c;
      to_world = &w;
    }
  });
  if (!camera) return std::nullopt;
  return CameraRays(*camera, *to_world, width, height);
}

// Samples a pixel-filter offset (separable Blackman-Harris, sampled by its
// tabulated inverse CDF, so the estimate converges to the filtered image
// without per-sample weights). `width` follows Cycles' "filter width": for
// Blackman-Harris Cycles doubles it (film.cpp, width *= 2), so the window
// spans [-width, width]; 1.5 px therefore covers 3 px.
glm::vec2 sample_pixel_filter(glm::vec2 u, float width = 1.5f);

}  // namespace engine::render
