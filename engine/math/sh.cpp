#include "engine/math/sh.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace engine::math {

ShBasis sh_eval(const glm::vec3& d) {
  const float x = d.x, y = d.y, z = d.z;
  const float x2 = x * x, y2 = y * y, z2 = z * z;
  ShBasis b;
  b[0] = 0.282094791773878f;
  b[1] = 0.488602511902920f * y;
  b[2] = 0.488602511902920f * z;
  b[3] = 0.488602511902920f * x;
  b[4] = 1.092548430592079f * x * y;
  b[5] = 1.092548430592079f * y * z;
  b[6] = 0.315391565252520f * (3.0f * z2 - 1.0f);
  b[7] = 1.092548430592079f * x * z;
  b[8] = 0.546274215296040f * (x2 - y2);
  b[9] = 0.590043589926644f * y * (3.0f * x2 - y2);
  b[10] = 2.890611442640554f * x * y * z;
  b[11] = 0.457045799464466f * y * (5.0f * z2 - 1.0f);
  b[12] = 0.373176332590115f * z * (5.0f * z2 - 3.0f);
  b[13] = 0.457045799464466f * x * (5.0f * z2 - 1.0f);
  b[14] = 1.445305721320277f * z * (x2 - y2);
  b[15] = 0.590043589926644f * x * (x2 - 3.0f * y2);
  b[16] = 2.503342941796705f * x * y * (x2 - y2);
  b[17] = 1.770130769779931f * y * z * (3.0f * x2 - y2);
  b[18] = 0.946174695757560f * x * y * (7.0f * z2 - 1.0f);
  b[19] = 0.669046543557289f * y * z * (7.0f * z2 - 3.0f);
  b[20] = 0.105785546915204f * (35.0f * z2 * z2 - 30.0f * z2 + 3.0f);
  b[21] = 0.669046543557289f * x * z * (7.0f * z2 - 3.0f);
  b[22] = 0.473087347878780f * (x2 - y2) * (7.0f * z2 - 1.0f);
  b[23] = 1.770130769779931f * x * z * (x2 - 3.0f * y2);
  b[24] = 0.625835735449176f * (x2 * (x2 - 3.0f * y2) - y2 * (3.0f * x2 - y2));
  return b;
}

double sh_eval_reference(int l, int m, const glm::dvec3& d) {
  const double ct = std::clamp(d.z, -1.0, 1.0);
  const double phi = std::atan2(d.y, d.x);
  const int am = std::abs(m);
  // Associated Legendre P_l^am(ct) without the Condon-Shortley phase.
  double pmm = 1.0;
  const double st = std::sqrt(std::max(0.0, 1.0 - ct * ct));
  for (int i = 1; i <= am; ++i) pmm *= (2.0 * i - 1.0) * st;
  double p = pmm;
  if (l > am) {
    double pmm1 = ct * (2.0 * am + 1.0) * pmm;
    p = pmm1;
    for (int ll = am + 2; ll <= l; ++ll) {
      const double pll = ((2.0 * ll - 1.0) * ct * pmm1 - (ll + am - 1.0) * pmm) / (ll - am);
      pmm = pmm1;
      pmm1 = pll;
      p = pll;
    }
  }
  double fact = 1.0;  // (l - am)! / (l + am)!
  for (int i = l - am + 1; i <= l + am; ++i) fact /= i;
  const double k = std::sqrt((2.0 * l + 1.0) / (4.0 * 3.14159265358979323846) * fact);
  if (m == 0) return k * p;
  return std::sqrt(2.0) * k * p * (m > 0 ? std::cos(m * phi) : std::sin(am * phi));
}

namespace {

constexpr int kBandOffset[5] = {0, 1, 10, 35, 84};

// Access to band l's block with m, n in [-l, l].
struct Band {
  std::vector<double> m;
  int l;
  explicit Band(int band) : m(static_cast<std::size_t>((2 * band + 1) * (2 * band + 1)), 0.0), l(band) {}
  double& at(int row, int col) { return m[static_cast<std::size_t>((row + l) * (2 * l + 1) + (col + l))]; }
  double at(int row, int col) const { return m[static_cast<std::size_t>((row + l) * (2 * l + 1) + (col + l))]; }
};

// P from Ivanic-Ruedenberg: built from band 1 (r) and the previous band.
double P(int i, int a, int b, int l, const Band& r, const Band& prev) {
  if (b == l) return r.at(i, 1) * prev.at(a, l - 1) - r.at(i, -1) * prev.at(a, -l + 1);
  if (b == -l) return r.at(i, 1) * prev.at(a, -l + 1) + r.at(i, -1) * prev.at(a, l - 1);
  return r.at(i, 0) * prev.at(a, b);
}

}  // namespace

ShRotation::ShRotation(const glm::mat3& R) {
  blocks_[0] = 1.0f;
  // Band 1 is proportional to (y, z, x): reorder the rotation's rows/columns.
  Band r(1);
  const int axis[3] = {1, 2, 0};  // m = -1 -> y, 0 -> z, 1 -> x
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j) r.at(i, j) = R[axis[j + 1]][axis[i + 1]];  // glm is column-major: R[col][row]
  Band prev = r;
  for (int i = 0; i < 9; ++i) blocks_[static_cast<std::size_t>(kBandOffset[1] + i)] = static_cast<float>(r.m[static_cast<std::size_t>(i)]);
  for (int l = 2; l <= kShDegree; ++l) {
    Band cur(l);
    for (int m = -l; m <= l; ++m)
      for (int n = -l; n <= l; ++n) {
        const double d = m == 0 ? 1.0 : 0.0;
        const double denom = std::abs(n) == l ? (2.0 * l) * (2.0 * l - 1.0) : (l + n) * static_cast<double>(l - n);
        const int am = std::abs(m);
        const double u = std::sqrt((l + m) * static_cast<double>(l - m) / denom);
        const double v = 0.5 * std::sqrt((1.0 + d) * (l + am - 1.0) * (l + am) / denom) * (1.0 - 2.0 * d);
        const double w = -0.5 * std::sqrt((l - am - 1.0) * (l - am) / denom) * (1.0 - d);
        double U = 0, V = 0, W = 0;
        if (u != 0) U = P(0, m, n, l, r, prev);
        if (v != 0) {
          if (m == 0) V = P(1, 1, n, l, r, prev) + P(-1, -1, n, l, r, prev);
          else if (m > 0) V = P(1, m - 1, n, l, r, prev) * std::sqrt(1.0 + (m == 1)) - P(-1, -m + 1, n, l, r, prev) * (1.0 - (m == 1));
          else V = P(1, m + 1, n, l, r, prev) * (1.0 - (m == -1)) + P(-1, -m - 1, n, l, r, prev) * std::sqrt(1.0 + (m == -1));
        }
        if (w != 0) {
          if (m > 0) W = P(1, m + 1, n, l, r, prev) + P(-1, -m - 1, n, l, r, prev);
          else W = P(1, m - 1, n, l, r, prev) - P(-1, -m + 1, n, l, r, prev);
        }
        cur.at(m, n) = u * U + v * V + w * W;
      }
    for (std::size_t i = 0; i < cur.m.size(); ++i) blocks_[static_cast<std::size_t>(kBandOffset[l]) + i] = static_cast<float>(cur.m[i]);
    prev = cur;
  }
}

void ShRotation::apply(const float* in, float* out) const {
  out[0] = in[0];
  for (int l = 1; l <= kShDegree; ++l) {
    const int n = 2 * l + 1, base = l * l;
    const float* b = &blocks_[static_cast<std::size_t>(kBandOffset[l])];
    for (int i = 0; i < n; ++i) {
      float s = 0;
      for (int j = 0; j < n; ++j) s += b[i * n + j] * in[base + j];
      out[base + i] = s;
    }
  }
}

float ShRotation::element(int row, int col) const {
  const int l = static_cast<int>(std::sqrt(static_cast<float>(row)));
  if (col < l * l || col >= (l + 1) * (l + 1)) return 0.0f;
  const int n = 2 * l + 1;
  return blocks_[static_cast<std::size_t>(kBandOffset[l] + (row - l * l) * n + (col - l * l))];
}

}  // namespace engine::math
