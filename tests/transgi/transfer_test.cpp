// Known answers for the transfer integrals: a Lambertian plane's transfer is
// (a / pi) times the clamped cosine's SH projection; dotting transfer with a
// constant unit light gives the directional albedo (a white-furnace check);
// a closed room with t beyond its size has zero transfer on the inside, and
// with a tiny t it is unoccluded again; the pooled BRDF-mixture estimator and
// a cosine-only estimator agree on a glossy surface.
#include <gtest/gtest.h>

#include <cmath>

#include "bake/transfer.h"
#include "engine/math/sampling.h"
#include "engine/scene/procedural.h"

using namespace transgi::bake;
using namespace engine;

namespace {

scene::SceneAssets assets_with(scene::MeshAsset mesh, material::Material mat) {
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  a.meshes.push_back(std::make_shared<scene::MeshAsset>(std::move(mesh)));
  a.materials = {mat};
  return a;
}

material::Material lambert(float a) {
  material::Material m;
  m.base_color_factor = glm::vec4(a, a, a, 1);
  m.metallic_factor = 0;
  m.roughness_factor = 1;
  m.specular_factor = 0;
  return m;
}

// (1/pi) * projection of max(0, n . d) onto Y_k, by brute-force quadrature.
std::array<double, 25> clamped_cosine_over_pi(glm::dvec3 n) {
  std::array<double, 25> c{};
  const int nt = 400, np = 800;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      const double ct = -1 + 2 * (i + 0.5) / nt, phi = 2 * math::kPi * (j + 0.5) / np;
      const double st = std::sqrt(1 - ct * ct);
      const glm::dvec3 d(st * std::cos(phi), st * std::sin(phi), ct);
      const double v = std::max(0.0, glm::dot(n, d)) / math::kPi * (2.0 / nt) * (2 * math::kPi / np);
      for (int l = 0; l <= 4; ++l)
        for (int m = -l; m <= l; ++m) c[static_cast<std::size_t>(math::sh_index(l, m))] += v * math::sh_eval_reference(l, m, d);
    }
  return c;
}

}  // namespace

TEST(Transfer, LambertianPlaneIsAlbedoTimesClampedCosine) {
  const float a = 0.6f;
  const auto assets = assets_with(scene::make_quad({1, 1}), lambert(a));
  const auto tracer = make_object_tracer(assets, 0);
  MeshTransfer mt(*tracer, *assets.meshes[0], assets, 1.0f);
  math::Pcg32 rng(3, 4);
  const SurfacePoint p = mt.sample_point(rng);
  EXPECT_NEAR(p.shading_normal.y, 1.0f, 1e-6f);
  const std::vector<glm::vec3> wo = {glm::normalize(glm::vec3(0.3f, 1, 0.2f)), glm::normalize(glm::vec3(-1, 0.2f, 0.5f))};
  std::vector<float> t(2 * kTransferValues);
  mt.estimate(p, wo, 16384, rng, t);
  const auto expected = clamped_cosine_over_pi({0, 1, 0});
  for (int j = 0; j < 2; ++j)
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 25; ++k)
        EXPECT_NEAR(t[static_cast<std::size_t>(j * 75 + c * 25 + k)], a * expected[static_cast<std::size_t>(k)], 4e-3)
            << "wo " << j << " channel " << c << " coefficient " << k;
}

TEST(Transfer, DotWithConstantUnitLightGivesTheDirectionalAlbedo) {
  // Constant radiance 1 has SH coefficient 2 sqrt(pi) on Y_0 only, so
  // t . L = integral f cos = the BRDF's directional albedo (a furnace).
  for (float specular : {0.0f, 1.0f}) {
    material::Material m = lambert(0.5f);
    m.specular_factor = specular;
    m.roughness_factor = 0.4f;
    const auto assets = assets_with(scene::make_quad({1, 1}), m);
    const auto tracer = make_object_tracer(assets, 0);
    MeshTransfer mt(*tracer, *assets.meshes[0], assets, 1.0f);
    math::Pcg32 rng(5, 6);
    const SurfacePoint p = mt.sample_point(rng);
    const glm::vec3 wo = glm::normalize(glm::vec3(0.4f, 0.7f, 0.1f));
    std::vector<float> t(kTransferValues);
    mt.estimate(p, std::span(&wo, 1), 8192, rng, t);
    const double dot = t[0] * 2.0 * std::sqrt(math::kPi);
    // Reference albedo by brute-force quadrature of the same BRDF.
    const math::Frame f = math::Frame::from_normal(p.shading_normal);
    const glm::vec3 wo_l = f.to_local(wo);
    double albedo = 0;
    const int n = 600;
    for (int i = 0; i < n; ++i)
      for (int jj = 0; jj < n; ++jj) {
        const double ct = (i + 0.5) / n, phi = 2 * math::kPi * (jj + 0.5) / n, st = std::sqrt(1 - ct * ct);
        const glm::vec3 wi(static_cast<float>(st * std::cos(phi)), static_cast<float>(st * std::sin(phi)), static_cast<float>(ct));
        albedo += material::brdf_eval(p.brdf, wo_l, wi).r * ct * (1.0 / n) * (2 * math::kPi / n);
      }
    EXPECT_NEAR(dot, albedo, 0.01 * albedo) << "specular " << specular << ": expected " << albedo << " got " << dot;
  }
}

TEST(Transfer, VisibilityDistanceDecidesWhatOccludes) {
  // Inside a closed 2 m room every direction hits a wall within ~3.5 m.
  const auto assets = assets_with(scene::make_box({1, 1, 1}, /*inward=*/true), lambert(0.5f));
  const auto tracer = make_object_tracer(assets, 0);
  math::Pcg32 rng(7, 8);
  const glm::vec3 wo(0, 0, 0);
  {
    MeshTransfer far(*tracer, *assets.meshes[0], assets, 10.0f);
    const SurfacePoint p = far.sample_point(rng);
    const glm::vec3 w = MeshTransfer::sample_outgoing(p, rng);
    std::vector<float> t(kTransferValues);
    far.estimate(p, std::span(&w, 1), 1024, rng, t);
    for (float v : t) EXPECT_EQ(v, 0.0f) << "everything is occluded within t = 10";
  }
  {
    MeshTransfer near_(*tracer, *assets.meshes[0], assets, 1e-3f);
    const SurfacePoint p = near_.sample_point(rng);
    const glm::vec3 w = MeshTransfer::sample_outgoing(p, rng);
    std::vector<float> t(kTransferValues);
    near_.estimate(p, std::span(&w, 1), 4096, rng, t);
    EXPECT_NEAR(t[0] * 2.0 * std::sqrt(math::kPi), 0.5, 0.01) << "nothing is closer than t = 1 mm: albedo 0.5";
  }
}

TEST(Transfer, MixtureAndCosineEstimatorsAgreeOnAGlossySurface) {
  material::Material m;
  m.base_color_factor = glm::vec4(0.9f, 0.7f, 0.4f, 1);
  m.metallic_factor = 1;
  m.roughness_factor = 0.35f;
  const auto assets = assets_with(scene::make_quad({1, 1}), m);
  const auto tracer = make_object_tracer(assets, 0);
  MeshTransfer mt(*tracer, *assets.meshes[0], assets, 1.0f);
  math::Pcg32 rng(9, 10);
  const SurfacePoint p = mt.sample_point(rng);
  const std::vector<glm::vec3> wo = {glm::normalize(glm::vec3(0.2f, 1, 0)), glm::normalize(glm::vec3(0.9f, 0.3f, 0))};
  std::vector<float> mix(2 * kTransferValues), cosine(2 * kTransferValues);
  mt.estimate(p, wo, 32768, rng, mix, Proposal::BrdfMixture);
  mt.estimate(p, wo, 262144, rng, cosine, Proposal::CosineOnly);
  double err = 0, norm = 0;
  for (std::size_t i = 0; i < mix.size(); ++i) {
    err += (mix[i] - cosine[i]) * (mix[i] - cosine[i]);
    norm += cosine[i] * cosine[i];
  }
  EXPECT_LT(std::sqrt(err / norm), 0.03) << "relative difference between the two unbiased estimators";
}
