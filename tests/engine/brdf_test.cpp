// Known-answer tests for the glTF BRDF: analytic Lambert albedo, white
// furnace energy bound, pdf normalisation, reciprocity, and consistency of
// sample() with eval()/pdf().
#include <gtest/gtest.h>

#include <cmath>

#include "engine/material/brdf.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"

using namespace engine::material;
using namespace engine::math;

namespace {

glm::vec3 dir_from_cos(float cos_theta, float phi) {
  const float s = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

struct Estimate {
  double mean = 0;
  double stderr_ = 0;
};

// Directional albedo E(wo) = integral f(wo, wi) cos(wi) dwi by importance
// sampling with brdf_sample, stratified over a sqrt(n) x sqrt(n) grid.
Estimate albedo(const BrdfParams& p, const glm::vec3& wo, int sqrt_n, std::uint64_t seed) {
  Pcg32 rng(seed, 7);
  double sum = 0, sum2 = 0;
  const int n = sqrt_n * sqrt_n;
  for (int i = 0; i < sqrt_n; ++i)
    for (int j = 0; j < sqrt_n; ++j) {
      const glm::vec2 u((static_cast<float>(i) + rng.next_float()) / static_cast<float>(sqrt_n),
                        (static_cast<float>(j) + rng.next_float()) / static_cast<float>(sqrt_n));
      BrdfSample s;
      double v = 0;
      if (brdf_sample(p, wo, u, rng.next_float(), s)) v = luminance(s.f) * s.wi.z / s.pdf;
      sum += v;
      sum2 += v * v;
    }
  Estimate e;
  e.mean = sum / n;
  e.stderr_ = std::sqrt(std::max(0.0, sum2 / n - e.mean * e.mean) / n);
  return e;
}

}  // namespace

TEST(Brdf, LambertAlbedoIsTheBaseColourExactly) {
  // specular = 0 and metallic = 0: f = base / pi; cosine sampling makes f cos / pdf = base.
  BrdfParams p{.base_color = glm::vec3(0.3f, 0.5f, 0.7f), .metallic = 0, .roughness = 0.7f, .specular = 0};
  const glm::vec3 wo = dir_from_cos(0.6f, 0.3f);
  const Estimate e = albedo(p, wo, 64, 1);
  EXPECT_NEAR(e.mean, luminance(p.base_color), 1e-5) << "expected " << luminance(p.base_color) << " got " << e.mean;
  EXPECT_NEAR(brdf_eval(p, wo, dir_from_cos(0.2f, 2.0f)).g, 0.5f / kPi, 1e-7);
}

namespace {

enum class Lobes { All, Glossy };
struct RgbEstimate {
  glm::dvec3 mean{0.0}, err{0.0};  // per channel: the estimate and its standard error
};
// Per channel, the integral over wi of f(wo, wi) cos(wi) (Lobes::All), or of
// f less its diffuse lobe (Lobes::Glossy), by importance sampling with
// brdf_sample over 256 x 256 strata.
RgbEstimate integral_with_cos(const BrdfParams& p, const glm::vec3& wo, Lobes lobes, std::uint64_t seed, std::uint64_t stream) {
  Pcg32 rng(seed, stream);
  const int sqrt_n = 256, n = sqrt_n * sqrt_n;
  glm::dvec3 sum(0.0), sum2(0.0);
  for (int i = 0; i < sqrt_n; ++i)
    for (int j = 0; j < sqrt_n; ++j) {
      const glm::vec2 u((static_cast<float>(i) + rng.next_float()) / sqrt_n, (static_cast<float>(j) + rng.next_float()) / sqrt_n);
      BrdfSample s;
      if (!brdf_sample(p, wo, u, rng.next_float(), s)) continue;
      const glm::vec3 f = lobes == Lobes::All ? s.f : s.f - brdf_eval_diffuse(p, wo, s.wi);
      const glm::dvec3 v = glm::dvec3(f) * static_cast<double>(s.wi.z / s.pdf);
      sum += v;
      sum2 += v * v;
    }
  RgbEstimate e;
  e.mean = sum / static_cast<double>(n);
  for (int k = 0; k < 3; ++k) e.err[k] = std::sqrt(std::max(0.0, sum2[k] / n - e.mean[k] * e.mean[k]) / n);
  return e;
}

}  // namespace

TEST(Brdf, DirectionalAlbedoIsTheIntegralOfEveryLobe) {
  // directional_albedo (tables, no sampling) against the integral of
  // f(wo, wi) cos(wi) over the hemisphere, estimated per channel by
  // importance sampling over 256 x 256 strata: a varnished brown wood, a
  // rough grey plastic, a Lambertian, gold, a half metal. Tolerance: four
  // standard errors plus 0.005 for the tables' interpolation. And the
  // difference from diffuse_albedo is what the specular layer adds: a
  // metal's whole albedo, a varnish's few percent (more at grazing angles).
  const BrdfParams materials[] = {
      {.base_color = glm::vec3(0.30f, 0.15f, 0.08f), .metallic = 0, .roughness = 0.35f, .specular = 1},
      {.base_color = glm::vec3(0.5f), .metallic = 0, .roughness = 0.8f, .specular = 0.5f},
      {.base_color = glm::vec3(0.3f, 0.5f, 0.7f), .metallic = 0, .roughness = 0.7f, .specular = 0},
      {.base_color = glm::vec3(1.0f, 0.78f, 0.34f), .metallic = 1, .roughness = 0.4f, .specular = 1},
      {.base_color = glm::vec3(0.6f, 0.6f, 0.6f), .metallic = 0.5f, .roughness = 0.5f, .specular = 1},
  };
  for (const BrdfParams& p : materials)
    for (const float cos_o : {0.15f, 0.5f, 0.95f}) {
      const glm::vec3 wo = dir_from_cos(cos_o, 0.7f);
      const RgbEstimate e = integral_with_cos(p, wo, Lobes::All, 3, 11);
      const glm::vec3 table = directional_albedo(p, cos_o);
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(table[k], e.mean[k], 4 * e.err[k] + 0.005)
            << "base " << p.base_color[k] << " metallic " << p.metallic << " roughness " << p.roughness << " cos_o " << cos_o;
      }
      EXPECT_GE(table.r + 1e-6f, diffuse_albedo(p).r) << "the specular layer only adds";
    }
  EXPECT_EQ(directional_albedo(materials[2], 0.5f), diffuse_albedo(materials[2])) << "no specular layer: the base colour";
  EXPECT_EQ(directional_albedo(materials[0], 0.0f), glm::vec3(0.0f));
}

TEST(Brdf, TheLayerAndMetalAlbedosAreTheGlossyLobesIntegrals) {
  // dielectric_layer_albedo and metal_albedo (tables) against the integral
  // of the glossy lobes alone, (f - f_diffuse) cos, by importance sampling
  // over 256 x 256 strata; tolerance four standard errors plus 0.005. And
  // the parts add up to directional_albedo (to float rounding).
  const BrdfParams materials[] = {
      {.base_color = glm::vec3(0.30f, 0.15f, 0.08f), .metallic = 0, .roughness = 0.35f, .specular = 1},
      {.base_color = glm::vec3(0.5f), .metallic = 0, .roughness = 0.8f, .specular = 0.5f, .specular_color = glm::vec3(1.0f, 0.5f, 0.2f)},
      {.base_color = glm::vec3(1.0f, 0.78f, 0.34f), .metallic = 1, .roughness = 0.4f, .specular = 1},
      {.base_color = glm::vec3(0.6f, 0.6f, 0.6f), .metallic = 0.5f, .roughness = 0.5f, .specular = 1},
  };
  for (const BrdfParams& p : materials)
    for (const float cos_o : {0.15f, 0.5f, 0.95f}) {
      const glm::vec3 wo = dir_from_cos(cos_o, 0.7f);
      const RgbEstimate e = integral_with_cos(p, wo, Lobes::Glossy, 5, 13);
      const glm::vec3 layer = dielectric_layer_albedo(p, cos_o), metal = metal_albedo(p, cos_o);
      const glm::vec3 glossy = (1.0f - p.metallic) * layer + p.metallic * metal;
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(glossy[k], e.mean[k], 4 * e.err[k] + 0.005)
            << "base " << p.base_color[k] << " metallic " << p.metallic << " roughness " << p.roughness << " cos_o " << cos_o;
      }
      const glm::vec3 parts = (1.0f - p.metallic) * (p.base_color * (1.0f - layer) + layer) + p.metallic * metal;
      const glm::vec3 whole = directional_albedo(p, cos_o);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(parts[k], whole[k], 1e-6f);
    }
  const BrdfParams lambert{.base_color = glm::vec3(0.5f), .specular = 0};
  EXPECT_EQ(dielectric_layer_albedo(lambert, 0.5f), glm::vec3(0.0f)) << "no layer";
}

TEST(Brdf, WhiteFurnaceEnergyNeverExceedsOne) {
  // A white (base 1) surface under uniform unit radiance reflects E(wo) <= 1
  // for every roughness, metallic value and view angle (single-scattering
  // GGX loses energy, it never gains it).
  for (float roughness : {0.0f, 0.05f, 0.2f, 0.5f, 0.8f, 1.0f})
    for (float metallic : {0.0f, 0.5f, 1.0f})
      for (float specular : {0.0f, 1.0f})
        for (float cos_o : {0.02f, 0.2f, 0.5f, 0.9f, 1.0f}) {
          const BrdfParams p{.base_color = glm::vec3(1.0f), .metallic = metallic, .roughness = roughness,
                             .specular = specular};
          const Estimate e = albedo(p, dir_from_cos(cos_o, 0.7f), 128, 3);
          EXPECT_LE(e.mean, 1.0 + 4.0 * e.stderr_ + 1e-4)
              << "roughness " << roughness << " metallic " << metallic << " specular " << specular << " cos_o "
              << cos_o << ": expected <= 1, got " << e.mean << " +- " << e.stderr_;
          EXPECT_GT(e.mean, 0.3) << "implausibly dark: roughness " << roughness << " metallic " << metallic;
          if (metallic == 0.0f) {
            // The albedo-scaled coupling makes a white dielectric reflect
            // exactly s E + (1 - s E) = 1 (up to the table's interpolation).
            EXPECT_NEAR(e.mean, 1.0, 4.0 * e.stderr_ + 0.01)
                << "white dielectric, roughness " << roughness << " specular " << specular << " cos_o " << cos_o;
          }
        }
}

TEST(Brdf, MetalAtNormalIncidenceSmoothReflectsF0) {
  // A near-mirror metal seen head-on reflects ~F0 (G -> 1, F(0) = F0).
  const BrdfParams p{.base_color = glm::vec3(0.9f, 0.6f, 0.3f), .metallic = 1, .roughness = 0.02f};
  const Estimate e = albedo(p, glm::vec3(0, 0, 1), 64, 5);
  EXPECT_NEAR(e.mean, luminance(p.base_color), 0.01) << "expected F0 luminance " << luminance(p.base_color);
}

TEST(Brdf, PdfIntegratesToTheSamplersSuccessRate) {
  // brdf_pdf is the density of the directions brdf_sample returns. Visible-
  // normal reflection sends some samples below the horizon (about half at
  // alpha = 1, head-on), which brdf_sample reports as failures, so the pdf
  // integrates over the upper hemisphere to P(success), measured here by
  // sampling; it is 1 for the cosine lobe. Quadrature is stratified in
  // (cos theta, phi). Lobes sharper than roughness 0.3 need a finer grid
  // than a unit test affords; the cap test below covers them.
  for (float roughness : {0.3f, 0.5f, 1.0f})
    for (float metallic : {0.0f, 1.0f})
      for (float cos_o : {0.3f, 0.8f}) {
        const BrdfParams p{.base_color = glm::vec3(0.5f), .metallic = metallic, .roughness = roughness};
        const glm::vec3 wo = dir_from_cos(cos_o, 0.0f);
        const int n = 1000;
        double sum = 0;
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j) {
            const float c = (static_cast<float>(i) + 0.5f) / n;
            const float phi = kTwoPi * (static_cast<float>(j) + 0.5f) / n;
            sum += brdf_pdf(p, wo, dir_from_cos(c, phi));
          }
        const double integral = sum * kTwoPi / (static_cast<double>(n) * n);

        Pcg32 rng(17, 2);
        const int trials = 200000;
        int ok = 0;
        for (int t = 0; t < trials; ++t) {
          BrdfSample s;
          ok += brdf_sample(p, wo, {rng.next_float(), rng.next_float()}, rng.next_float(), s) ? 1 : 0;
        }
        const double success = static_cast<double>(ok) / trials;
        EXPECT_NEAR(integral, success, 0.01) << "roughness " << roughness << " metallic " << metallic << " cos_o "
                                             << cos_o << ": expected " << success << ", got " << integral;
        if (metallic == 0.0f) {
          EXPECT_GT(success, 0.9) << "the cosine lobe never fails";
        }
      }
}

TEST(Brdf, SampledDirectionsFollowTheReportedPdf) {
  // For any g, E[g(wi) / pdf(wi)] over sample() equals integral g. With
  // g = 1 on a cap around the mirror direction, this checks sample() against
  // pdf() even for sharp lobes: the estimate must equal the cap's solid angle.
  for (float roughness : {0.05f, 0.2f, 0.6f}) {
    const BrdfParams p{.base_color = glm::vec3(0.5f), .metallic = 1, .roughness = roughness};
    const glm::vec3 wo = dir_from_cos(0.7f, 0.0f);
    const glm::vec3 axis = glm::vec3(-wo.x, -wo.y, wo.z);
    const float cap_cos = 0.9f;  // solid angle 2 pi (1 - 0.9), fully above the horizon here
    Pcg32 rng(11, 3);
    const int n = 400000;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      BrdfSample s;
      if (!brdf_sample(p, wo, {rng.next_float(), rng.next_float()}, rng.next_float(), s)) continue;
      if (glm::dot(s.wi, axis) > cap_cos) sum += 1.0 / s.pdf;
    }
    const double expected = kTwoPi * (1.0 - cap_cos);
    EXPECT_NEAR(sum / n, expected, 0.02 * expected)
        << "roughness " << roughness << ": expected " << expected << ", got " << sum / n;
  }
}

TEST(Brdf, Reciprocity) {
  Pcg32 rng(42, 1);
  for (int i = 0; i < 2000; ++i) {
    const BrdfParams p{.base_color = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()),
                       .metallic = rng.next_float(),
                       .roughness = rng.next_float(),
                       .specular = rng.next_float(),
                       .specular_color = glm::vec3(rng.next_float(), 1.0f, rng.next_float()) * 2.0f};
    const glm::vec3 a = sample_uniform_hemisphere({rng.next_float(), rng.next_float()});
    const glm::vec3 b = sample_uniform_hemisphere({rng.next_float(), rng.next_float()});
    const glm::vec3 fab = brdf_eval(p, a, b), fba = brdf_eval(p, b, a);
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(fab[c], fba[c], 1e-5f * std::max(1.0f, std::abs(fab[c])))
          << "f(a,b) vs f(b,a), channel " << c << " case " << i;
  }
}

TEST(Brdf, BelowTheSurfaceIsZero) {
  const BrdfParams p{};
  EXPECT_EQ(brdf_eval(p, {0, 0, 1}, {0, 0.6f, -0.8f}), glm::vec3(0.0f));
  EXPECT_EQ(brdf_pdf(p, {0, 0.6f, -0.8f}, {0, 0, 1}), 0.0f);
  BrdfSample s;
  EXPECT_FALSE(brdf_sample(p, {0, 0.6f, -0.8f}, {0.5f, 0.5f}, 0.5f, s));
}

TEST(Ggx, NormalDistributionProjectsToOne) {
  // integral D(h) cos(h) dh = 1 over the hemisphere.
  for (float alpha : {0.1f, 0.4f, 1.0f}) {
    const int n = 4000;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      const float c = (static_cast<float>(i) + 0.5f) / n;
      sum += ggx_d(alpha, c) * c;
    }
    const double integral = sum * kTwoPi / n;
    EXPECT_NEAR(integral, 1.0, 2e-3) << "alpha " << alpha;
  }
}
