#pragma once
// A probe's lat-long radiance map (paper Section 5.2; 100 x 50 by default)
// in the project's convention (engine/scene/environment.h): texel (x, y)
// covers u in [x/W, (x+1)/W), v in [y/H, (y+1)/H) of the map's parameters,
// v = 0 being +Y. Solid angles are exact per texel.
#include <array>
#include <vector>

#include <glm/glm.hpp>

#include "engine/math/sh.h"

namespace transgi::probes {

struct MapLayout {
  int width = 100;
  int height = 50;

  [[nodiscard]] int texel_count() const { return width * height; }
  [[nodiscard]] int texel_of(const glm::vec3& unit_dir) const;
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
