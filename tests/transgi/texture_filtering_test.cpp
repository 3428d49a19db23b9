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

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/math/rng.h"
#include "engine/render/camera_rays.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "shading/gbuffer.h"

using namespace engine;

TEST(TextureFiltering, ACheckerWallAtOneSampleMatchesItsManySampleReference) {
  const int n = 512, size = 48, ref_spp = 256;
  app::App app(app::AppOptions{.jobs = {.threads = 2}});
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({1, 1}))};
  scene::Texture t;
  t.width = t.height = n;
  t.rgba.resize(static_cast<std::size_t>(n) * n * 4);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      std::uint8_t* p = &t.rgba[(static_cast<std::size_t>(y) * n + x) * 4];
      p[0] = p[1] = p[2] = ((x + y) & 1) ? 255 : 0;
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
  const ecs::Entity camera = w.spawn();
  transform::Transform ct = transform::Transform::from_translation({0, 2.2f, 2.2f});  // 45 degrees above the wall
  ct.rotation = glm::quatLookAt(glm::normalize(glm::vec3(0, -1, -1)), glm::vec3(0, 1, 0));
  w.emplace<transform::Transform>(camera, ct);
  w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 0.6f});
  app.update();
  const auto& rt = w.resource<rt::RtScene>();
  const auto& assets = w.resource<scene::SceneAssets>();
  const render::CameraRays rays(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), size, size);

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
