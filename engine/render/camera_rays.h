#pragma once
// Pinhole camera rays from a scene::Camera and its WorldTransform. Pixel
// (0, 0) is the top-left; the camera looks down its local -Z with +Y up.
#include "engine/rt/ray.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"

namespace engine::render {

struct CameraRays {
  CameraRays(const scene::Camera& camera, const transform::Similarity& to_world, int width, int height);
  // film = pixel coordinates with sub-pixel offset, e.g. (x + 0.5, y + 0.5).
  [[nodiscard]] rt::Ray generate(glm::vec2 film) const;
  [[nodiscard]] glm::vec3 position() const { return origin_; }

 private:
  glm::vec3 origin_;
  glm::mat3 rotation_;
  float tan_half_y_, tan_half_x_;
  int width_, height_;
};

// Samples a pixel-filter offset in [-width/2, width/2]^2 (separable
// Blackman-Harris, the shape Cycles uses; width 1.5 px by default), so the
// estimate converges to the filtered image without per-sample weights.
glm::vec2 sample_pixel_filter(glm::vec2 u, float width = 1.5f);

}  // namespace engine::render
