#pragma once
// A probe's lat-long radiance map (paper Section 5.2; 100 x 50 by default)
// in the project's convention (engine/scene/environment.h): texel (x, y)
// covers u in [x/W, (x+1)/W), v in [y/H, (y+1)/H) of the map's parameters,
// v = 0 being +Y. Solid angles are exact per texel.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "engine/math/sh.h"

namespace transgi::probes {

// atan2 and acos to about 1e-5 rad, branch-free and inlinable, so loops of
// them vectorise. Signed zeros follow std::atan2 (atan2(+-0, -0) = +-pi).
inline float fast_atan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float hi = std::max(ax, ay), lo = std::min(ax, ay);
  const float z = hi > 0 ? lo / hi : 0.0f, z2 = z * z;
  // Minimax odd polynomial for atan on [0, 1].
  float a = z * (0.99997726f + z2 * (-0.33262347f + z2 * (0.19354346f + z2 * (-0.11643287f + z2 * (0.05265332f + z2 * -0.01172120f)))));
  a = ay > ax ? 1.57079633f - a : a;
  a = std::signbit(x) ? 3.14159265f - a : a;
  return std::signbit(y) ? -a : a;
}
inline float fast_acos(float x) {
  // Abramowitz and Stegun 4.4.46 (error 2e-8 on [0, 1]), mirrored for x < 0.
  const float ax = std::min(std::abs(x), 1.0f);
  const float p = 1.5707963050f + ax * (-0.2145988016f + ax * (0.0889789874f + ax * (-0.0501743046f + ax * (0.0308918810f +
                  ax * (-0.0170881256f + ax * (0.0066700901f + ax * -0.0012624911f))))));
  const float r = std::sqrt(1.0f - ax) * p;
  return x < 0 ? 3.14159265f - r : r;
}

struct MapLayout {
  int width = 100;
  int height = 50;

  [[nodiscard]] int texel_count() const { return width * height; }
  // The texel holding a direction, by polynomial atan2 and acos (errors
  // below 2e-5 rad, a two-thousandth of a texel at 100 x 50): it runs once
  // per probe-ray splat and eight times per shaded pixel. The reference,
  // through Environment::direction_to_uv, is texel_of_reference; they differ
  // only for directions that close to a texel border (tested).
  [[nodiscard]] int texel_of(const glm::vec3& unit_dir) const {
    const glm::vec2 at = texel_position(unit_dir);
    const int x = std::min(width - 1, std::max(0, static_cast<int>(at.x)));
    const int y = std::min(height - 1, std::max(0, static_cast<int>(at.y)));
    return y * width + x;
  }
  // Where a direction falls on the map, in texels (texel x spans [x, x + 1)):
  // what a filtered read interpolates at.
  [[nodiscard]] glm::vec2 texel_position(const glm::vec3& unit_dir) const {
    const float u = fast_atan2(unit_dir.x, -unit_dir.z) * 0.15915494f;  // / 2 pi
    const float v = fast_acos(unit_dir.y) * 0.31830989f;                 // / pi
    const float uw = u < 0 ? u + 1.0f : u;
    return {uw * static_cast<float>(width), v * static_cast<float>(height)};
  }
  [[nodiscard]] int texel_of_reference(const glm::vec3& unit_dir) const;
  [[nodiscard]] glm::vec3 direction_of(int texel) const;  // texel centre
  [[nodiscard]] double solid_angle(int texel) const;

  bool operator==(const MapLayout&) const = default;
};

// SH projection of one map: L[c][k] = sum_texels radiance * integral_texel Y_k,
// with each texel's integral of Y_k precomputed by sub-sampling (the same
// exact-per-texel rule as the environment projection) and summed in double.
class MapProjector {
 public:
  explicit MapProjector(MapLayout layout, int subsamples = 4);
  // radiance: texel_count() RGB values. out: 75 values [c * 25 + k].
  void project(const glm::vec3* radiance, float* out) const;
  [[nodiscard]] const MapLayout& layout() const { return layout_; }
  // Per texel, the integral of each Y_k over it (what the GPU kernel uploads).
  [[nodiscard]] const std::vector<std::array<float, engine::math::kShCount>>& basis_integrals() const { return basis_integrals_; }

 private:
  MapLayout layout_;
  std::vector<std::array<float, engine::math::kShCount>> basis_integrals_;  // per texel
};

// Per-band window against ringing (Sloan 2008, "Stupid SH tricks"): Hanning
// weights w_l = (1 + cos(pi l / (L + 1))) / 2. Multiplies coefficients in place.
void apply_hanning_window(float* coefficients_rgb, int degree = engine::math::kShDegree);

// Radiance in direction d from SH coefficients, clamped at zero.
glm::vec3 evaluate_clamped(const float* coefficients_rgb, const glm::vec3& d);

}  // namespace transgi::probes
