#include "engine/scene/environment.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/math/sampling.h"

namespace engine::scene {

using math::kPi;
using math::kTwoPi;

Environment::Environment(image::ImageRGB image, float strength, const glm::mat4& matrix)
    : image_(std::move(image)), strength_(strength) {
  // The matrix may carry scale; only its rotation matters for directions.
  const glm::mat3 m(matrix);
  to_world_ = glm::mat3(glm::normalize(m[0]), glm::normalize(m[1]), glm::normalize(m[2]));
  to_local_ = glm::inverse(to_world_);
  loaded_to_world_ = to_world_;
  const int w = image_.width, h = image_.height;
  std::vector<float> weights(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    const float sin_theta = std::sin(kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(h));
    for (int x = 0; x < w; ++x)
      weights[static_cast<std::size_t>(y) * w + x] = math::luminance(image_.at(x, y)) * sin_theta;
  }
  distribution_ = math::AliasDistribution2D(weights, w, h);
}

void Environment::set_yaw(float radians) {
  yaw_ = radians;
  const float c = std::cos(radians), s = std::sin(radians);
  const glm::mat3 about_y(glm::vec3(c, 0, -s), glm::vec3(0, 1, 0), glm::vec3(s, 0, c));  // columns
  to_world_ = about_y * loaded_to_world_;
  to_local_ = glm::transpose(to_world_);
}

glm::vec2 Environment::direction_to_uv(const glm::vec3& l) {
  float u = std::atan2(l.x, -l.z) / kTwoPi;
  if (u < 0) u += 1.0f;
  if (u >= 1.0f) u = 0.0f;
  const float v = std::acos(std::clamp(l.y, -1.0f, 1.0f)) / kPi;
  return {u, v};
}

glm::vec3 Environment::uv_to_direction(glm::vec2 uv) {
  const float phi = kTwoPi * uv.x, theta = kPi * uv.y;
  return {std::sin(phi) * std::sin(theta), std::cos(theta), -std::cos(phi) * std::sin(theta)};
}

glm::vec3 Environment::radiance(const glm::vec3& world_dir) const {
  if (!valid()) return glm::vec3(0.0f);
  const glm::vec2 uv = direction_to_uv(glm::normalize(to_local_ * world_dir));
  const int x = std::min(image_.width - 1, static_cast<int>(uv.x * static_cast<float>(image_.width)));
  const int y = std::min(image_.height - 1, static_cast<int>(uv.y * static_cast<float>(image_.height)));
  return strength_ * image_.at(x, y);
}

glm::vec3 Environment::sample(glm::vec2 u, glm::vec3* world_dir, float* pdf) const {
  if (!valid()) {
    *world_dir = glm::vec3(0.0f, 1.0f, 0.0f);
    *pdf = 0.0f;
    return glm::vec3(0.0f);
  }
  float map_pdf = 0;
  std::uint32_t texel = 0;
  const glm::vec2 uv = distribution_.sample(u, &map_pdf, &texel);
  const float sin_theta = std::sin(kPi * uv.y);
  const glm::vec3 local = uv_to_direction(uv);
  *world_dir = glm::normalize(to_world_ * local);
  // dA(uv) = 2 pi^2 sin(theta) d(omega)^-1
  *pdf = sin_theta > 0 ? map_pdf / (2.0f * kPi * kPi * sin_theta) : 0.0f;
  // The sampled texel's radiance, which the pdf is of (the direction may lie
  // on its edge, which radiance(direction) could place in the next texel).
  const auto w = static_cast<std::uint32_t>(image_.width);
  return strength_ * image_.at(static_cast<int>(texel % w), static_cast<int>(texel / w));
}

float Environment::pdf(const glm::vec3& world_dir) const {
  if (!valid()) return 0.0f;
  const glm::vec2 uv = direction_to_uv(glm::normalize(to_local_ * world_dir));
  const float sin_theta = std::sin(kPi * uv.y);
  return sin_theta > 0 ? distribution_.pdf(uv) / (2.0f * kPi * kPi * sin_theta) : 0.0f;
}

Environment uniform_environment(glm::vec3 radiance) {
  return Environment(image::ImageRGB(1, 1, radiance), 1.0f, glm::mat4(1.0f));
}

}  // namespace engine::scene
