// Texture filtering in the G-buffer (issue 14, item 4): a wall papered with
// a checker of 1-texel black and white squares, seen at an angle at 48 x 48
// pixels (4 to 30 texels across each pixel). With one sample per pixel and
// point sampling, each pixel reads one bilinear blend of a few texels,
// anywhere from 0 to 1; with ray cones and mips it reads the pixel's average,
// as a rasteriser would. The reference is 256 point samples per pixel over
// the pixel filter, whose own noise is at most 0.5 / sqrt(256) = 0.031 RMSE.
// Tolerance: RMSE 0.045 against it (noise plus the isotropic filter's
// error), and every filtered pixel within 0.03 of the known average 0.5. What the network and the shading get is this
// G-buffer's albedo.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/math/rng.h"
#include "engine/render/camera_rays.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "engine/render/temporal_aa.h"
#include "shading/gbuffer.h"
#include "shading/realtime_gi.h"

using namespace engine;

namespace {

// A 2 x 2 m wall (the quad's plane, normal +Y) papered with an n x n texture
// whose texel (x, y) is grey level texel(x, y), and a camera.
struct TexturedWall {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity camera;

  TexturedWall(int n, const std::function<std::uint8_t(int, int)>& texel, const transform::Transform& camera_at) {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({1, 1}))};
    scene::Texture t;
    t.width = t.height = n;
    t.rgba.resize(static_cast<std::size_t>(n) * n * 4);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        std::uint8_t* p = &t.rgba[(static_cast<std::size_t>(y) * n + x) * 4];
        p[0] = p[1] = p[2] = texel(x, y);
        p[3] = 255;
      }
    t.build_mips(true);
    a.textures = {std::move(t)};
    material::Material m = lambert(glm::vec3(1));
    m.base_color_texture = 0;
    a.materials = {m};
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    ecs::World& w = app.world();
    const ecs::Entity wall = w.spawn();
    w.emplace<transform::Transform>(wall);
    w.emplace<scene::MeshInstance>(wall, scene::MeshInstance{0});
    camera = w.spawn();
    w.emplace<transform::Transform>(camera, camera_at);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 0.6f});
    app.update();
  }
  [[nodiscard]] render::CameraRays rays(int size) {
    ecs::World& w = app.world();
    return render::CameraRays(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), size, size);
  }
};

}  // namespace

TEST(TextureFiltering, ACheckerWallAtOneSampleMatchesItsManySampleReference) {
  const int n = 512, size = 48, ref_spp = 256;
  transform::Transform ct = transform::Transform::from_translation({0, 2.2f, 2.2f});  // 45 degrees above the wall
  ct.rotation = glm::quatLookAt(glm::normalize(glm::vec3(0, -1, -1)), glm::vec3(0, 1, 0));
  TexturedWall scene(n, [](int x, int y) { return static_cast<std::uint8_t>(((x + y) & 1) ? 255 : 0); }, ct);
  const auto& rt = scene.app.world().resource<rt::RtScene>();
  const auto& assets = scene.app.world().resource<scene::SceneAssets>();
  const render::CameraRays rays = scene.rays(size);

  double sq_filtered = 0, sq_point = 0, worst = 0;
  int pixels = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const std::size_t pixel = static_cast<std::size_t>(y) * size + x;
      auto sample = [&](std::uint64_t s, float spread) {
        math::Pcg32 rng = math::make_rng(3, pixel, s);
        const glm::vec2 u(rng.next_float(), rng.next_float());
        return transgi::shading::trace_gsample(rt, assets, rays.generate_filtered(x, y, u, 1.5f), nullptr, spread);
      };
      const transgi::shading::GSample filtered = sample(0, rays.pixel_spread()), point = sample(0, 0.0f);
      if (!filtered.hit) continue;
      double ref = 0;
      int hits = 0;
      for (int s = 1; s <= ref_spp; ++s) {
        const transgi::shading::GSample r = sample(static_cast<std::uint64_t>(s), 0.0f);
        if (r.hit) {
          ref += r.albedo.g;
          ++hits;
        }
      }
      if (hits < ref_spp) continue;  // pixels on the wall's edge
      ref /= hits;
      sq_filtered += (filtered.albedo.g - ref) * (filtered.albedo.g - ref);
      sq_point += (point.albedo.g - ref) * (point.albedo.g - ref);
      worst = std::max(worst, std::abs(filtered.albedo.g - 0.5));
      ++pixels;
    }
  ASSERT_GT(pixels, size * size / 2) << "the wall must fill most of the view";
  const double rmse_filtered = std::sqrt(sq_filtered / pixels), rmse_point = std::sqrt(sq_point / pixels);
  std::printf("%d pixels: RMSE against %d spp: %.4f with ray cones and mips, %.4f point-sampled; worst filtered pixel %.4f from 0.5\n",
              pixels, ref_spp, rmse_filtered, rmse_point, worst);
  EXPECT_LT(rmse_filtered, 0.045) << "expected the 256-spp reference within RMSE 0.045, got " << rmse_filtered;
  EXPECT_LT(worst, 0.03);
  EXPECT_GT(rmse_point, 0.1) << "point sampling must alias here (measured 0.17), or this test shows nothing";
}

// The real-time frame's textures under temporal antialiasing: each frame
// reads one sample per pixel at a jittered point, and a still view shows the
// mean over the jitter cycle, which already averages the pixel's area. Read
// at the footprint's own mip level, the mip's filter blurs on top of that
// average; TemporalAaSettings::texture_lod_bias (-1) reads a level finer.
// The wall faces the camera at 1.9 texels a pixel, papered with stripes 2
// texels wide: the reference is each pixel's box average of 256 point
// samples (bilinear at the finest level), its contrast the mean |v - 0.5|.
// The jitter cycle's mean at the bias must keep that contrast within 10 %;
// at no bias the test expects it visibly lower (below 85 %), or it shows
// nothing.
TEST(TextureFiltering, AJitterCycleAtTheTaaMipBiasKeepsAStripedWallsContrast) {
  const int n = 512, size = 48, ref_spp = 256, phases = 4;  // 4 x 4 jitter points
  // 2 m over 512 texels, yfov 0.6 over 48 pixels: at distance d a pixel spans
  // 3.3 d texels; d = 0.575 gives 1.9.
  transform::Transform ct = transform::Transform::from_translation({0.013f, 0.575f, 0.021f});
  ct.rotation = glm::quatLookAt(glm::vec3(0, -1, 0), glm::vec3(0, 0, -1));
  TexturedWall scene(n, [](int x, int) { return static_cast<std::uint8_t>(((x / 2) & 1) ? 255 : 0); }, ct);
  const auto& rt = scene.app.world().resource<rt::RtScene>();
  const auto& assets = scene.app.world().resource<scene::SceneAssets>();
  const render::CameraRays rays = scene.rays(size);
  const float bias = render::TemporalAaSettings{}.texture_lod_bias;
  ASSERT_EQ(bias, -1.0f);

  const auto cycle_mean = [&](float lod_bias) {
    std::vector<double> mean(static_cast<std::size_t>(size) * size, 0.0);
    transgi::shading::GBuffer g;
    for (int j = 0; j < phases * phases; ++j) {
      const glm::vec2 jitter((static_cast<float>(j % phases) + 0.5f) / phases - 0.5f, (static_cast<float>(j / phases) + 0.5f) / phases - 0.5f);
      transgi::shading::trace_gbuffer(rt, assets, rays, size, size, g, nullptr, nullptr, jitter, lod_bias);
      for (std::size_t p = 0; p < mean.size(); ++p) mean[p] += g.albedo[p].g / (phases * phases);
    }
    return mean;
  };
  const std::vector<double> biased = cycle_mean(bias), unbiased = cycle_mean(0.0f);
  double contrast_ref = 0, contrast_biased = 0, contrast_unbiased = 0;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const std::size_t pixel = static_cast<std::size_t>(y) * size + x;
      double ref = 0;
      for (int s = 0; s < ref_spp; ++s) {
        math::Pcg32 rng = math::make_rng(5, pixel, static_cast<std::uint64_t>(s));
        const glm::vec2 film(static_cast<float>(x) + rng.next_float(), static_cast<float>(y) + rng.next_float());
        const transgi::shading::GSample r = transgi::shading::trace_gsample(rt, assets, rays.generate(film), nullptr, 0.0f);
        ASSERT_TRUE(r.hit) << "the wall must fill the view";
        ref += r.albedo.g / ref_spp;
      }
      contrast_ref += std::abs(ref - 0.5);
      contrast_biased += std::abs(biased[pixel] - 0.5);
      contrast_unbiased += std::abs(unbiased[pixel] - 0.5);
    }
  const double kept = contrast_biased / contrast_ref, kept_unbiased = contrast_unbiased / contrast_ref;
  std::printf("stripes' contrast over the jitter cycle, of the reference's %.4f: %.3f at lod bias %.0f, %.3f at none\n",
              contrast_ref / (size * size), kept, bias, kept_unbiased);
  EXPECT_NEAR(kept, 1.0, 0.1);
  EXPECT_LT(kept_unbiased, 0.85) << "at the footprint's own level the mip should blur the stripes, or this test shows nothing";
}
