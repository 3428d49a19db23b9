#include "render/sh_light.h"

#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "engine/math/sampling.h"

namespace transgi::render {

using engine::math::kShCount;

ShRgb project_environment(const engine::scene::Environment& env) {
  std::array<double, 3 * kShCount> acc{};
  const auto& img = env.image();
  const int w = img.width, h = img.height;
  for (int y = 0; y < h; ++y) {
    const double theta0 = engine::math::kPi * y / h, theta1 = engine::math::kPi * (y + 1) / h;
    const double d_omega = (2.0 * engine::math::kPi / w) * (std::cos(theta0) - std::cos(theta1));  // exact texel solid angle
    for (int x = 0; x < w; ++x) {
      const glm::vec3 local = engine::scene::Environment::uv_to_direction(
          {(static_cast<float>(x) + 0.5f) / static_cast<float>(w), (static_cast<float>(y) + 0.5f) / static_cast<float>(h)});
      // Evaluate through the environment so its matrix and strength apply.
      const glm::vec3 world = glm::normalize(env.to_world(local));
      const glm::vec3 L = env.radiance(world);
      const engine::math::ShBasis b = engine::math::sh_eval(world);
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < kShCount; ++k) acc[static_cast<std::size_t>(c * kShCount + k)] += L[c] * b[static_cast<std::size_t>(k)] * d_omega;
    }
  }
  ShRgb out;
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>(acc[i]);
  return out;
}

ShRgb rotate_to_object(const ShRgb& world, const glm::quat& object_rotation) {
  // ShRotation(M) maps f to f(M^T d); we need L(R d), i.e. M = R^T.
  const engine::math::ShRotation rot(glm::transpose(glm::mat3_cast(object_rotation)));
  ShRgb out;
  for (int c = 0; c < 3; ++c) rot.apply(world.data() + c * kShCount, out.data() + c * kShCount);
  return out;
}

glm::vec3 shade(const ShRgb& light, const float* t) {
  glm::vec3 out(0.0f);
  for (int c = 0; c < 3; ++c) {
    float s = 0;
    for (int k = 0; k < kShCount; ++k) s += light[static_cast<std::size_t>(c * kShCount + k)] * t[c * kShCount + k];
    out[c] = s;
  }
  return out;
}

}  // namespace transgi::render
