// SH convention tests: closed form vs Legendre recurrence, orthonormality by
// quadrature, clamped-cosine zonal coefficients, and rotation:
// rotate(project(f)) == project(f rotated).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/math/sh.h"

using namespace engine::math;

namespace {

// Gauss-Legendre nodes/weights on [-1, 1] (Golub-Welsch via Newton on P_n).
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.resize(n);
  w.resize(n);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(3.14159265358979323846 * (i + 0.75) / (n + 0.5));
    for (int it = 0; it < 100; ++it) {
      double p0 = 1, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      const double dp = n * (z * p1 - p0) / (z * z - 1);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    double p0 = 1, p1 = z;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    const double dp = n * (z * p1 - p0) / (z * z - 1);
    x[i] = z;
    w[i] = 2 / ((1 - z * z) * dp * dp);
  }
}

// Exact (for band-limited integrands) spherical quadrature.
void for_each_quadrature_point(int n_theta, const std::function<void(const glm::dvec3&, double)>& fn) {
  std::vector<double> x, w;
  gauss_legendre(n_theta, x, w);
  const int n_phi = 2 * n_theta;
  for (int i = 0; i < n_theta; ++i)
    for (int j = 0; j < n_phi; ++j) {
      const double phi = 2 * 3.14159265358979323846 * (j + 0.5) / n_phi;
      const double st = std::sqrt(1 - x[i] * x[i]);
      fn({st * std::cos(phi), st * std::sin(phi), x[i]}, w[i] * 2 * 3.14159265358979323846 / n_phi);
    }
}

std::vector<double> project(const std::function<double(const glm::dvec3&)>& f, int n_theta = 64) {
  std::vector<double> c(kShCount, 0.0);
  for_each_quadrature_point(n_theta, [&](const glm::dvec3& d, double w) {
    const ShBasis y = sh_eval(glm::vec3(d));
    const double v = f(d);
    for (int k = 0; k < kShCount; ++k) c[k] += v * y[k] * w;
  });
  return c;
}

}  // namespace

TEST(Sh, ClosedFormMatchesTheLegendreRecurrence) {
  Pcg32 rng(1, 1);
  for (int i = 0; i < 200; ++i) {
    const glm::vec3 d = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const ShBasis y = sh_eval(d);
    for (int l = 0; l <= kShDegree; ++l)
      for (int m = -l; m <= l; ++m)
        ASSERT_NEAR(y[sh_index(l, m)], sh_eval_reference(l, m, glm::dvec3(d)), 2e-6)
            << "l " << l << " m " << m << " at (" << d.x << ", " << d.y << ", " << d.z << ")";
  }
}

TEST(Sh, BasisIsOrthonormalByQuadrature) {
  double gram[kShCount][kShCount] = {};
  for_each_quadrature_point(32, [&](const glm::dvec3& d, double w) {
    const ShBasis y = sh_eval(glm::vec3(d));
    for (int a = 0; a < kShCount; ++a)
      for (int b = 0; b < kShCount; ++b) gram[a][b] += static_cast<double>(y[a]) * y[b] * w;
  });
  for (int a = 0; a < kShCount; ++a)
    for (int b = 0; b < kShCount; ++b)
      EXPECT_NEAR(gram[a][b], a == b ? 1.0 : 0.0, 2e-6) << "<Y" << a << ", Y" << b << ">";
}

TEST(Sh, ClampedCosineHasTheKnownZonalCoefficients) {
  // max(0, cos theta) about +Z: c0 = sqrt(pi)/2, c1 = sqrt(pi/3), c2 = sqrt(5 pi)/8, c3 = 0,
  // c4 = -sqrt(pi)/16; every m != 0 coefficient is 0.
  const auto c = project([](const glm::dvec3& d) { return std::max(0.0, d.z); }, 256);
  const double pi = 3.14159265358979323846;
  const double expected[5] = {std::sqrt(pi) / 2, std::sqrt(pi / 3), std::sqrt(5 * pi) / 8, 0.0, -std::sqrt(pi) / 16};
  for (int l = 0; l <= kShDegree; ++l)
    for (int m = -l; m <= l; ++m)
      EXPECT_NEAR(c[sh_index(l, m)], m == 0 ? expected[l] : 0.0, 1e-4) << "l " << l << " m " << m;
}

TEST(Sh, RotatingCoefficientsEqualsProjectingTheRotatedFunction) {
  // A band-limited test function (a combination of basis functions, so the
  // projection is exact) and a smooth non-band-limited one.
  const std::vector<std::function<double(const glm::dvec3&)>> functions = {
      [](const glm::dvec3& d) { return 0.3 + d.x - 0.5 * d.y * d.z + 2 * d.x * d.x * d.y * d.z - d.z * d.z * d.z; },
      [](const glm::dvec3& d) { return std::exp(2.0 * glm::dot(d, glm::normalize(glm::dvec3(0.3, -0.5, 0.8)))); }};
  Pcg32 rng(7, 3);
  for (int trial = 0; trial < 5; ++trial) {
    const glm::vec3 axis = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const glm::mat3 R = glm::mat3_cast(glm::angleAxis(kTwoPi * rng.next_float(), axis));
    const ShRotation rot(R);
    for (const auto& f : functions) {
      const auto cf = project(f);
      // g(d) = f(R^T d): f rotated by R.
      const auto cg = project([&](const glm::dvec3& d) { return f(glm::dvec3(glm::transpose(R) * glm::vec3(d))); });
      float in[kShCount], out[kShCount];
      for (int k = 0; k < kShCount; ++k) in[k] = static_cast<float>(cf[k]);
      rot.apply(in, out);
      for (int k = 0; k < kShCount; ++k)
        EXPECT_NEAR(out[k], cg[k], 2e-4 * (1 + std::abs(cg[k]))) << "trial " << trial << " coefficient " << k;
    }
  }
}

TEST(Sh, RotationMatrixIsOrthogonal) {
  const ShRotation rot(glm::mat3_cast(glm::angleAxis(1.1f, glm::normalize(glm::vec3(1, 2, 3)))));
  for (int a = 0; a < kShCount; ++a)
    for (int b = 0; b < kShCount; ++b) {
      double s = 0;
      for (int k = 0; k < kShCount; ++k) s += rot.element(k, a) * rot.element(k, b);
      EXPECT_NEAR(s, a == b ? 1.0 : 0.0, 1e-5) << a << "," << b;
    }
}
