#include "probes/probe_rays.h"

#include <cmath>

#include "engine/math/sampling.h"

namespace transgi::probes {

std::vector<glm::vec3> spherical_fibonacci(int n) {
  std::vector<glm::vec3> d(static_cast<std::size_t>(n));
  const float golden = 0.5f * (1.0f + std::sqrt(5.0f));
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - (2.0f * static_cast<float>(i) + 1.0f) / static_cast<float>(n);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    const float phi = engine::math::kTwoPi * std::fmod(static_cast<float>(i) / golden, 1.0f);
    d[static_cast<std::size_t>(i)] = {r * std::cos(phi), r * std::sin(phi), z};
  }
  return d;
}

glm::quat random_rotation(engine::math::Pcg32& rng) {
  const float u1 = rng.next_float(), u2 = engine::math::kTwoPi * rng.next_float(), u3 = engine::math::kTwoPi * rng.next_float();
  const float a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return glm::normalize(glm::quat(b * std::cos(u3), a * std::sin(u2), a * std::cos(u2), b * std::sin(u3)));
}

}  // namespace transgi::probes
