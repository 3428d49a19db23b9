#pragma once
// Real spherical harmonics up to degree 4 (25 coefficients): the project's
// one SH convention, used by the bake, the probes and the shading.
//
// Convention: orthonormal real SH without the Condon-Shortley phase, index
// k = l (l + 1) + m, polar axis +Z of the frame the direction is given in:
//   Y_0^0 = 1 / (2 sqrt(pi))
//   Y_1^{-1} = c y,  Y_1^0 = c z,  Y_1^1 = c x,   c = sqrt(3 / (4 pi))
// (so band 1 is proportional to (y, z, x), which is what makes the
// Ivanic-Ruedenberg rotation recursion apply directly). Higher bands follow
// Y_l^m = sqrt(2) K_l^|m| P_l^|m|(cos theta) {cos(m phi) if m > 0, sin(|m| phi) if m < 0},
// with P_l^m the associated Legendre functions without (-1)^m.
#include <array>

#include <glm/glm.hpp>

namespace engine::math {

inline constexpr int kShDegree = 4;
inline constexpr int kShCount = (kShDegree + 1) * (kShDegree + 1);  // 25

using ShBasis = std::array<float, kShCount>;

constexpr int sh_index(int l, int m) { return l * (l + 1) + m; }

// All 25 basis functions at a unit direction (closed-form polynomials).
ShBasis sh_eval(const glm::vec3& d);
// Reference evaluation from the Legendre recurrence in double precision (tests).
double sh_eval_reference(int l, int m, const glm::dvec3& d);

// Rotation of SH coefficient vectors: if g(d) = f(R^T d) (f rotated by R),
// then coefficients(g) = ShRotation(R) * coefficients(f). Block diagonal,
// one (2l+1)^2 block per band, built with the Ivanic-Ruedenberg recursion
// (J. Phys. Chem. 1996, with the 1998 errata).
class ShRotation {
 public:
  explicit ShRotation(const glm::mat3& rotation);
  // out = M * in, for one channel (in and out may not alias).
  void apply(const float* in, float* out) const;
  [[nodiscard]] float element(int row, int col) const;  // of the full 25x25 matrix

 private:
  // band l block stored at offset kBandOffset[l], row-major (2l+1)^2
  std::array<float, 1 + 9 + 25 + 49 + 81> blocks_{};
};

}  // namespace engine::math
