#include "engine/render/camera_rays.h"

#include <array>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "engine/math/distribution.h"
#include "engine/math/sampling.h"

namespace engine::render {

CameraRays::CameraRays(const scene::Camera& camera, const transform::Similarity& to_world, int width, int height)
    : origin_(to_world.translation),
      to_world_(to_world),
      rotation_(glm::mat3_cast(to_world.rotation)),
      width_(width),
      height_(height) {
  tan_half_y_ = std::tan(0.5f * camera.yfov_radians);
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  tan_half_x_ = tan_half_y_ * aspect;
}

rt::Ray CameraRays::generate_filtered(int x, int y, glm::vec2 u, float filter_width) const {
  const glm::vec2 centre(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
  return generate(centre + sample_pixel_filter(u, filter_width));
}

glm::vec2 sample_pixel_filter(glm::vec2 u, float width) {
  // Tabulated inverse CDF of the 1D Blackman-Harris window over [-w/2, w/2].
  static const math::Distribution1D table = [] {
    constexpr int n = 256;
    std::array<float, n> f{};
    for (int i = 0; i < n; ++i) {
      const double x = (i + 0.5) / n;  // window position in [0, 1]
      const double a = 2.0 * math::kPi * x;
      f[static_cast<std::size_t>(i)] =
          static_cast<float>(0.35875 - 0.48829 * std::cos(a) + 0.14128 * std::cos(2 * a) - 0.01168 * std::cos(3 * a));
    }
    return math::Distribution1D(f);
  }();
  const float x = table.sample_continuous(u.x, nullptr, nullptr);
  const float y = table.sample_continuous(u.y, nullptr, nullptr);
  return {(2.0f * x - 1.0f) * width, (2.0f * y - 1.0f) * width};
}

}  // namespace engine::render
