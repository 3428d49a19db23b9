#pragma once
// Warps from the unit square to directions and shapes, with their pdfs.
// Conventions: local frames have +z as the normal; pdfs are per solid angle.
#include <cmath>
#include <cstdint>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

namespace engine::math {

inline constexpr float kPi = glm::pi<float>();
inline constexpr float kInvPi = 1.0f / kPi;
inline constexpr float kTwoPi = 2.0f * kPi;

struct Frame {
  glm::vec3 t, b, n;
  // Duff et al. 2017, "Building an Orthonormal Basis, Revisited": branchless, exact.
  static Frame from_normal(const glm::vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    return {glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x), glm::vec3(b, sign + n.y * n.y * a, -n.y), n};
  }
  [[nodiscard]] glm::vec3 to_local(const glm::vec3& v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  [[nodiscard]] glm::vec3 to_world(const glm::vec3& v) const { return v.x * t + v.y * b + v.z * n; }
};

// Point k of the R2 sequence (Roberts 2018: steps of 1 / the plastic
// number and its square), shifted by `offset` modulo 1: any run of
// consecutive points covers the unit square evenly. Double precision, so
// k in the millions (a frame count) keeps its spacing.
inline glm::vec2 r2_point(std::uint64_t k, glm::vec2 offset = glm::vec2(0.5f)) {
  constexpr double a1 = 0.75487766624669276, a2 = 0.56984029099805327;
  const double kk = static_cast<double>(k % (std::uint64_t{1} << 40));
  const double x = static_cast<double>(offset.x) + kk * a1, y = static_cast<double>(offset.y) + kk * a2;
  return {static_cast<float>(x - std::floor(x)), static_cast<float>(y - std::floor(y))};
}

inline glm::vec2 sample_concentric_disk(glm::vec2 u) {
  const glm::vec2 o = 2.0f * u - 1.0f;
  if (o.x == 0 && o.y == 0) return {0, 0};
  float r, theta;
  if (std::abs(o.x) > std::abs(o.y)) {
    r = o.x;
    theta = 0.25f * kPi * (o.y / o.x);
  } else {
    r = o.y;
    theta = 0.5f * kPi - 0.25f * kPi * (o.x / o.y);
  }
  return r * glm::vec2(std::cos(theta), std::sin(theta));
}

inline glm::vec3 sample_cosine_hemisphere(glm::vec2 u) {
  const glm::vec2 d = sample_concentric_disk(u);
  const float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}
inline float cosine_hemisphere_pdf(float cos_theta) { return cos_theta > 0 ? cos_theta * kInvPi : 0.0f; }

inline glm::vec3 sample_uniform_sphere(glm::vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = kTwoPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float kUniformSpherePdf = 1.0f / (4.0f * kPi);

inline glm::vec3 sample_uniform_hemisphere(glm::vec2 u) {
  const float z = u.x;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = kTwoPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
// Uniform direction in the cone of half-angle r around +z.
inline glm::vec3 sample_uniform_cone(glm::vec2 u, float cos_r) {
  const float z = 1.0f - u.x * (1.0f - cos_r), s = std::sqrt(std::max(0.0f, 1.0f - z * z)), phi = kTwoPi * u.y;
  return {s * std::cos(phi), s * std::sin(phi), z};
}

inline constexpr float kUniformHemispherePdf = 1.0f / (2.0f * kPi);

// Uniform point on a triangle as barycentrics (b1, b2); b0 = 1 - b1 - b2.
// Heitz 2019's low-distortion square-to-triangle map.
inline glm::vec2 sample_uniform_triangle(glm::vec2 u) {
  float b0, b1;
  if (u.x < u.y) {
    b0 = u.x / 2;
    b1 = u.y - b0;
  } else {
    b1 = u.y / 2;
    b0 = u.x - b1;
  }
  return {b1, 1.0f - b0 - b1};
}

inline float power_heuristic(float pdf_a, float pdf_b) {
  const float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  if (std::isinf(a)) return 1.0f;
  return (a + b) > 0 ? a / (a + b) : 0.0f;
}

inline float luminance(const glm::vec3& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

}  // namespace engine::math
