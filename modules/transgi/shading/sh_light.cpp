#include "shading/sh_light.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "engine/math/sampling.h"

namespace transgi::shading {

using engine::math::kShCount;

ShRgb project_environment(const engine::scene::Environment& env) {
  // Lookups are nearest-texel, so each texel is constant radiance over its
  // patch of the sphere: integrate Y_k over every patch with enough
  // sub-samples that even a tiny map (a few texels) projects exactly enough
  // (a constant sky must give zero above band 0). Sub-cells use their exact
  // solid angle; accumulation is in double.
  std::array<double, 3 * kShCount> acc{};
  const auto& img = env.image();
  const int w = img.width, h = img.height;
  const int sub_x = std::max(1, (1024 + w - 1) / w), sub_y = std::max(1, (512 + h - 1) / h);
  const double pi = engine::math::kPi;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec3 L = env.strength() * img.at(x, y);
      std::array<double, kShCount> yint{};
      for (int sy = 0; sy < sub_y; ++sy) {
        const double v0 = (y + static_cast<double>(sy) / sub_y) / h, v1 = (y + (sy + 1.0) / sub_y) / h;
        const double d_omega = (2.0 * pi / (static_cast<double>(w) * sub_x)) * (std::cos(pi * v0) - std::cos(pi * v1));
        const double v = 0.5 * (v0 + v1);
        for (int sx = 0; sx < sub_x; ++sx) {
          const double u = (x + (sx + 0.5) / sub_x) / w;
          const glm::vec3 local = engine::scene::Environment::uv_to_direction({static_cast<float>(u), static_cast<float>(v)});
          const engine::math::ShBasis b = engine::math::sh_eval(glm::normalize(env.to_world(local)));
          for (int k = 0; k < kShCount; ++k) yint[static_cast<std::size_t>(k)] += b[static_cast<std::size_t>(k)] * d_omega;
        }
      }
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < kShCount; ++k) acc[static_cast<std::size_t>(c * kShCount + k)] += L[c] * yint[static_cast<std::size_t>(k)];
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
