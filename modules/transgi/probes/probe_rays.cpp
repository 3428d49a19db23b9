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

namespace {
// Shoemake's uniform rotation from a point of the unit cube.
glm::quat rotation_from_cube(float u1, float v2, float v3) {
  const float u2 = engine::math::kTwoPi * v2, u3 = engine::math::kTwoPi * v3;
  const float a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return glm::normalize(glm::quat(b * std::cos(u3), a * std::sin(u2), a * std::cos(u2), b * std::sin(u3)));
}

float radical_inverse(std::uint64_t i, std::uint64_t base) {
  double inv = 1.0 / static_cast<double>(base), f = inv, r = 0;
  for (; i > 0; i /= base, f *= inv) r += static_cast<double>(i % base) * f;
  return static_cast<float>(r);
}
}  // namespace

glm::quat random_rotation(engine::math::Pcg32& rng) {
  const float u1 = rng.next_float(), u2 = rng.next_float(), u3 = rng.next_float();
  return rotation_from_cube(u1, u2, u3);
}

glm::quat low_discrepancy_rotation(std::uint64_t index) {
  return rotation_from_cube(radical_inverse(index + 1, 2), radical_inverse(index + 1, 3), radical_inverse(index + 1, 5));
}

}  // namespace transgi::probes
