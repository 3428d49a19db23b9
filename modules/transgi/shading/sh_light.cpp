#include "shading/sh_light.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "engine/math/sampling.h"

namespace transgi::shading {

using engine::math::kShCount;

ShRgb project_environment(const engine::scene::Environment& env) {
  // Each texel's integral of Y_k over its patch, then times its radiance;
  // accumulation in double (engine::scene::for_each_patch_sample's rule).
  std::array<double, 3 * kShCount> acc{};
  const auto& img = env.image();
  std::array<double, kShCount> yint{};
  int at_x = -1, at_y = -1;
  const auto flush = [&] {
    if (at_x < 0) return;
    const glm::vec3 L = env.strength() * img.at(at_x, at_y);
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < kShCount; ++k) acc[static_cast<std::size_t>(c * kShCount + k)] += L[c] * yint[static_cast<std::size_t>(k)];
    yint.fill(0.0);
  };
  engine::scene::for_each_patch_sample(env, 0, img.height, [&](int x, int y, const glm::vec3& dir, double d_omega) {
    if (x != at_x || y != at_y) {
      flush();
      at_x = x;
      at_y = y;
    }
    const engine::math::ShBasis b = engine::math::sh_eval(dir);
    for (int k = 0; k < kShCount; ++k) yint[static_cast<std::size_t>(k)] += b[static_cast<std::size_t>(k)] * d_omega;
  });
  flush();
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

glm::vec3 sh_irradiance(const float* L, const glm::vec3& n) {
  // Clamped-cosine convolution weights per band: pi, 2pi/3, pi/4, 0, -pi/24.
  constexpr float kA[5] = {3.14159265f, 2.09439510f, 0.78539816f, 0.0f, -0.13089969f};
  const auto y = engine::math::sh_eval(n);
  glm::vec3 e(0.0f);
  for (int c = 0; c < 3; ++c) {
    float s = 0;
    for (int l = 0; l <= 4; ++l)
      for (int m = -l; m <= l; ++m) {
        const int k = engine::math::sh_index(l, m);
        s += kA[l] * L[c * 25 + k] * y[static_cast<std::size_t>(k)];
      }
    e[c] = std::max(0.0f, s);
  }
  return e;
}

}  // namespace transgi::shading
