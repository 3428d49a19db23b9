#include "engine/material/specular_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>

#include "engine/material/brdf.h"

namespace engine::material {

namespace {

constexpr int kMuSize = kAlbedoTableMu;
constexpr int kAlphaSize = kAlbedoTableAlpha;
constexpr int kStrata = 40;  // kStrata^2 VNDF samples per table entry

// Node grids in t = sqrt(mu) and r = sqrt(alpha): both change fastest near
// zero (grazing views, mirror-like lobes), and the end nodes sit exactly at
// the range limits so lookups never clamp to an interior value.
constexpr float kMinMu = 1e-4f;
float t_at(int i) { return static_cast<float>(i) / (kMuSize - 1); }
float mu_at(int i) { return std::max(kMinMu, t_at(i) * t_at(i)); }
float r_min() { return std::sqrt(kMinAlpha); }
float r_at(int j) { return r_min() + (1.0f - r_min()) * static_cast<float>(j) / (kAlphaSize - 1); }
float alpha_at(int j) { return r_at(j) * r_at(j); }

struct Tables {
  std::array<SpecularAlbedo, kMuSize * kAlphaSize> directional{};
  std::array<SpecularAlbedo, kAlphaSize> average{};
};

SpecularAlbedo integrate(float mu, float alpha) {
  // VNDF sampling: for a sampled wi the estimator of integral F D V cos_i is F * G2 / G1(wo).
  const glm::vec3 wo(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  double a = 0, b = 0;
  for (int i = 0; i < kStrata; ++i)
    for (int j = 0; j < kStrata; ++j) {
      const glm::vec2 u((static_cast<float>(i) + 0.5f) / kStrata, (static_cast<float>(j) + 0.5f) / kStrata);
      const glm::vec3 h = sample_ggx_vndf(alpha, wo, u);
      const glm::vec3 wi = glm::reflect(-wo, h);
      if (wi.z <= 0) continue;
      const float g1 = smith_g1(alpha, mu);
      const float g2 = smith_v_height_correlated(alpha, mu, wi.z) * 4.0f * mu * wi.z;
      const float w = g1 > 0 ? g2 / g1 : 0.0f;
      const float c = std::clamp(glm::dot(wo, h), 0.0f, 1.0f);
      const float f5 = std::pow(1.0f - c, 5.0f);
      a += (1.0 - f5) * w;
      b += f5 * w;
    }
  const double n = kStrata * kStrata;
  return {static_cast<float>(a / n), static_cast<float>(b / n)};
}

Tables build_tables() {
  Tables t;
  {
    for (int j = 0; j < kAlphaSize; ++j) {
      for (int i = 0; i < kMuSize; ++i)
        t.directional[static_cast<std::size_t>(j * kMuSize + i)] = integrate(mu_at(i), alpha_at(j));
      // 2 * integral E(mu) mu dmu = 4 * integral E(t^2) t^3 dt, trapezoid rule on the t nodes.
      double avg_a = 0, avg_b = 0;
      for (int i = 0; i + 1 < kMuSize; ++i) {
        const auto& e0 = t.directional[static_cast<std::size_t>(j * kMuSize + i)];
        const auto& e1 = t.directional[static_cast<std::size_t>(j * kMuSize + i + 1)];
        const double w0 = std::pow(t_at(i), 3.0), w1 = std::pow(t_at(i + 1), 3.0);
        const double dt = t_at(i + 1) - t_at(i);
        avg_a += 4.0 * 0.5 * (e0.a * w0 + e1.a * w1) * dt;
        avg_b += 4.0 * 0.5 * (e0.b * w0 + e1.b * w1) * dt;
      }
      t.average[static_cast<std::size_t>(j)] = {static_cast<float>(avg_a), static_cast<float>(avg_b)};
    }
  }
  return t;
}

// Built on first use. A function-local static costs one guard load per call;
// std::call_once cost about 1 % of a real-time frame (one call per BRDF
// evaluation).
const Tables& tables() {
  static const Tables t = build_tables();
  return t;
}

// Node-grid coordinate of x in [0, 1] mapped to [0, size - 1].
void locate(float x, int size, int& i0, float& t) {
  const float g = std::clamp(x, 0.0f, 1.0f) * static_cast<float>(size - 1);
  i0 = std::min(static_cast<int>(g), size - 2);
  t = g - static_cast<float>(i0);
}
float r_coord(float alpha) {
  return (std::sqrt(std::clamp(alpha, kMinAlpha, 1.0f)) - r_min()) / (1.0f - r_min());
}

}  // namespace

SpecularAlbedo ggx_albedo(float mu, float alpha) {
  const Tables& tb = tables();
  int i, j;
  float tu, ta;
  locate(std::sqrt(std::clamp(mu, 0.0f, 1.0f)), kMuSize, i, tu);
  locate(r_coord(alpha), kAlphaSize, j, ta);
  auto at = [&](int ii, int jj) { return tb.directional[static_cast<std::size_t>(jj * kMuSize + ii)]; };
  const SpecularAlbedo e00 = at(i, j), e10 = at(i + 1, j), e01 = at(i, j + 1), e11 = at(i + 1, j + 1);
  auto lerp2 = [&](float v00, float v10, float v01, float v11) {
    return (1 - ta) * ((1 - tu) * v00 + tu * v10) + ta * ((1 - tu) * v01 + tu * v11);
  };
  return {lerp2(e00.a, e10.a, e01.a, e11.a), lerp2(e00.b, e10.b, e01.b, e11.b)};
}

SpecularAlbedo ggx_average_albedo(float alpha) {
  const Tables& tb = tables();
  int j;
  float ta;
  locate(r_coord(alpha), kAlphaSize, j, ta);
  const SpecularAlbedo e0 = tb.average[static_cast<std::size_t>(j)], e1 = tb.average[static_cast<std::size_t>(j + 1)];
  return {(1 - ta) * e0.a + ta * e1.a, (1 - ta) * e0.b + ta * e1.b};
}

const SpecularAlbedo* ggx_albedo_directional_table() { return tables().directional.data(); }
const SpecularAlbedo* ggx_albedo_average_table() { return tables().average.data(); }

}  // namespace engine::material
