// Object-scale TransGI end to end on the committed furnace scene: a
// Lambertian sphere (albedo 0.8) under a white sky of radiance 1. A constant
// sky is exactly representable in SH, so t . L must give 0.8 with
// ground-truth transfer, and close to it with a small trained network. And
// a textured quad under the same sky, which a demodulated network keeps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <glm/gtc/quaternion.hpp>

#include "bake/trainer.h"
#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "shading/gbuffer.h"
#include "engine/math/sampling.h"
#include "runtime/transgi_plugin.h"
#include "shading/transfer_renderer.h"

using namespace transgi;
using namespace engine;
namespace shading = transgi::shading;

namespace {
struct Furnace {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity camera;
  Furnace() {
    app.add_plugin<rt::RtPlugin>();
    const auto r = scene::load_gltf(app.world(), std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/furnace/scene.gltf");
    for (ecs::Entity e : r.entities)
      if (app.world().has<scene::Camera>(e)) camera = e;
    app.update();
  }
  const scene::SceneAssets& assets() { return app.world().resource<scene::SceneAssets>(); }
  shading::TransferRenderResult render(const model::TransferModel& m, shading::TransferSource source) {
    auto& w = app.world();
    const engine::render::CameraRays cam(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), 24, 24);
    const auto light = shading::project_environment(*assets().environment);
    shading::TransferRenderResult r;
    app.jobs().run([&] {
      r = shading::render_transfer(w.resource<rt::RtScene>(), assets(), m, cam, 24, 24, shading::constant_light(light), &*assets().environment, source,
                                  {.spp = 1, .ground_truth_rays = 1024});
    });
    return r;
  }
};

double centre_mean(const image::ImageRGB& img) {
  double s = 0;
  for (int y = 9; y < 15; ++y)
    for (int x = 9; x < 15; ++x) s += img.at(x, y).g;
  return s / 36;
}
}  // namespace

TEST(ObjectRender, ProjectedConstantSkyIsExact) {
  Furnace f;
  const auto light = shading::project_environment(*f.assets().environment);
  EXPECT_NEAR(light[0], 2.0 * std::sqrt(math::kPi), 1e-4) << "constant 1 projects to 2 sqrt(pi) on Y_0";
  for (int k = 1; k < 25; ++k) EXPECT_NEAR(light[static_cast<std::size_t>(k)], 0.0, 1e-4) << "coefficient " << k;
}

TEST(ObjectRender, GroundTruthTransferGivesAlbedoTimesSky) {
  Furnace f;
  const auto m = bake::make_untrained_model(f.assets(), 7, model::MlpLayout{.width = 8, .hidden_layers = 1}, 1);
  const auto r = f.render(m, shading::TransferSource::GroundTruth);
  EXPECT_NEAR(centre_mean(r.image), 0.8, 0.015) << "expected albedo 0.8 x sky 1";
  EXPECT_NEAR(r.image.at(0, 0).g, 1.0f, 1e-3f) << "background shows the sky";
}

TEST(ObjectRender, TrainedNetworkReproducesTheFurnace) {
  Furnace f;
  bake::DatasetSettings ds;
  ds.points = 2000;
  ds.rays = 256;
  ds.outgoing_per_point = 4;
  const auto data = bake::generate_dataset(f.assets(), ds);
  auto m = bake::make_untrained_model(f.assets(), 7, model::MlpLayout{.width = 32, .hidden_layers = 2}, 1);
  bake::TrainSettings ts;
  ts.iterations = 800;
  ts.batch = 512;
  ts.learning_rate = 3e-3f;
  bake::Trainer trainer(data, f.assets(), m, ts);
  for (int i = 0; i < ts.iterations; ++i) trainer.step();
  const auto r = f.render(m, shading::TransferSource::Network);
  EXPECT_NEAR(centre_mean(r.image), 0.8, 0.04) << "the decoded transfer under a white sky";
}

namespace {
// A quad with a checker of orange and blue squares (4 x 4 on the quad),
// under a white sky: every pixel's light is its own albedo x 1.
struct CheckerUnderSky {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity camera;
  static constexpr glm::vec3 kOrange{0.9f, 0.45f, 0.1f}, kBlue{0.1f, 0.3f, 0.9f};
  CheckerUnderSky() {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({1, 1}))};
    scene::Texture t;
    const int n = 64;  // 4 x 4 squares of 16 x 16 texels: bilinear filtering blends only at their edges
    t.width = t.height = n;
    t.rgba.resize(static_cast<std::size_t>(n) * n * 4);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::vec3 c = ((x / 16 + y / 16) & 1) ? kOrange : kBlue;
        for (int k = 0; k < 3; ++k)  // sRGB-encoded, as a glTF base colour texture is
          t.rgba[static_cast<std::size_t>(y * n + x) * 4 + static_cast<std::size_t>(k)] =
              static_cast<std::uint8_t>(std::lround(255.0f * std::pow(c[k], 1.0f / 2.2f)));
        t.rgba[static_cast<std::size_t>(y * n + x) * 4 + 3] = 255;
      }
    t.build_mips(true);
    a.textures = {std::move(t)};
    material::Material m = lambert(glm::vec3(1.0f));
    m.base_color_texture = 0;
    a.materials = {m};
    a.environment = scene::uniform_environment(glm::vec3(1.0f));
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    ecs::World& w = app.world();
    const ecs::Entity quad = w.spawn();
    w.emplace<transform::Transform>(quad);
    w.emplace<scene::MeshInstance>(quad, scene::MeshInstance{0});
    camera = w.spawn();
    transform::Transform ct = transform::Transform::from_translation({0.0f, 2.0f, 0.0f});
    ct.rotation = glm::quatLookAtRH(glm::vec3(0, -1, 0), glm::vec3(0, 0, -1));
    w.emplace<transform::Transform>(camera, ct);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 0.7f});
    app.update();
  }
  const scene::SceneAssets& assets() { return app.world().resource<scene::SceneAssets>(); }
  // GI / albedo per channel over the quad's pixels inside a square (the
  // albedo the same everywhere a sample of the pixel may land): its extremes.
  struct Ratios {
    glm::vec3 lo{1e9f}, hi{-1e9f};
    struct Pixel {
      int x, y;
      glm::vec3 albedo, ratio;
    };
    std::vector<Pixel> pixels;
  };
  Ratios ratios(const image::ImageRGB& gi) {
    auto& w = app.world();
    const engine::render::CameraRays cam(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), gi.width, gi.height);
    Ratios r;
    int pixels = 0;
    for (int y = 0; y < gi.height; ++y)
      for (int x = 0; x < gi.width; ++x) {
        const auto albedo_at = [&](float fx, float fy) {
          return shading::trace_gsample(w.resource<rt::RtScene>(), assets(), cam.generate({fx, fy}), nullptr);
        };
        const shading::GSample s = albedo_at(x + 0.5f, y + 0.5f);
        if (!s.hit) continue;
        // render_transfer's sample may lie anywhere under its 1.5-pixel filter.
        bool inside = true;
        for (float oy = -1.0f; oy <= 2.0f && inside; oy += 0.75f)
          for (float ox = -1.0f; ox <= 2.0f && inside; ox += 0.75f) {
            const shading::GSample c = albedo_at(x + ox, y + oy);
            inside = c.hit && glm::all(glm::lessThan(glm::abs(c.albedo - s.albedo), glm::vec3(1e-3f)));
          }
        if (!inside) continue;
        ++pixels;
        r.lo = glm::min(r.lo, gi.at(x, y) / s.albedo);
        r.hi = glm::max(r.hi, gi.at(x, y) / s.albedo);
        r.pixels.push_back({x, y, s.albedo, gi.at(x, y) / s.albedo});
      }
    EXPECT_GT(pixels, gi.width * gi.height / 8);
    return r;
  }
};
}  // namespace

namespace {
// A decoder that ignores its inputs and predicts one grey transfer: t_c0 =
// 1 / (2 sqrt(pi)), so a white sky of radiance 1 (L_0 = 2 sqrt(pi)) gives
// t . L = 1 in every channel. What a network that learned light but not
// albedo would predict.
std::shared_ptr<model::TransferModel> grey_light_model(const scene::SceneAssets& assets, bool demodulated) {
  auto m = std::make_shared<model::TransferModel>(
      bake::make_untrained_model(assets, 7, model::MlpLayout{.inputs = 16, .width = 16, .hidden_layers = 1, .outputs = 75}, 1));
  auto& p = m->decoder.params();
  std::fill(p.begin(), p.end(), 0.0f);
  const auto& l = m->decoder.layout();
  for (int c = 0; c < 3; ++c) p[l.bias_offset(l.hidden_layers) + static_cast<std::size_t>(c * 25)] = 0.5f / std::sqrt(math::kPi);
  m->demodulated = demodulated;
  return m;
}
}  // namespace

// Issue 37: a demodulated model's transfer is over albedo, so every shading
// path multiplies the pixel's own albedo back: with a network that learned
// grey light, the GI is the texture itself (GI / albedo = 1 on orange and
// blue texels alike); the same network read as holding the albedo gives a
// grey quad (GI / albedo = 1 / albedo).
TEST(ObjectRender, ADemodulatedModelsGiCarriesThePixelsOwnAlbedo) {
  CheckerUnderSky scene;
  auto& w = scene.app.world();
  const int size = 32;
  const engine::render::CameraRays cam(w.get<scene::Camera>(scene.camera), w.get<transform::WorldTransform>(scene.camera), size, size);
  const auto light = shading::project_environment(*scene.assets().environment);
  for (const bool demodulated : {true, false}) {
    const auto m = grey_light_model(scene.assets(), demodulated);
    shading::TransferRenderResult r;
    scene.app.jobs().run([&] {
      r = shading::render_transfer(w.resource<rt::RtScene>(), scene.assets(), *m, cam, size, size, shading::constant_light(light),
                                   &*scene.assets().environment, shading::TransferSource::Network, {.spp = 1});
    });
    const auto q = scene.ratios(r.image);
    if (demodulated) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(q.lo[c], 1.0f, 1e-3f) << "channel " << c;
        EXPECT_NEAR(q.hi[c], 1.0f, 1e-3f) << "channel " << c;
      }
    } else {
      EXPECT_GT(q.hi.b / q.lo.b, 5.0f) << "grey light over orange and blue texels";
    }
  }
}

// The real-time path upsamples the light over albedo and multiplies each
// pixel's albedo back: through the plugin (half-res decoding, checkerboard
// reuse, the probes' light, in the direct pass: the sky's), the light over
// albedo of an orange pixel and a blue one a few pixels apart is the same
// (the probes' light varies across the quad, smoothly).
TEST(ObjectRender, TheRealTimePathMultipliesEachPixelsAlbedoBack) {
  CheckerUnderSky scene;
  auto& w = scene.app.world();
  runtime::TransGISettings settings = runtime::realtime_preset();
  settings.probes.map = probes::MapLayout{16, 8};
  settings.taa.enabled = false;  // this frame's own samples
  scene.app.add_plugin<runtime::TransGIPlugin>(settings);
  runtime::attach_latent_meshes(w, grey_light_model(scene.assets(), true));
  const ecs::Entity volume = w.spawn();
  w.emplace<runtime::ProbeVolume>(volume, runtime::ProbeVolume{.min = {-1.5f, 0.1f, -1.5f}, .max = {1.5f, 1.5f, 1.5f}, .dims = {3, 2, 3}});
  auto& frame = w.resource<runtime::GiFrame>();
  for (int f = 0; f < 8; ++f) {
    frame.width = 32;
    frame.height = 32;
    scene.app.jobs().run([&] { scene.app.update(); });
  }
  const auto q = scene.ratios(frame.direct);
  int pairs = 0;
  float worst = 0;
  for (const auto& a : q.pixels)
    for (const auto& b : q.pixels) {
      if (std::abs(a.x - b.x) + std::abs(a.y - b.y) > 5 || a.albedo.b < b.albedo.b) continue;
      if (glm::all(glm::lessThan(glm::abs(a.albedo - b.albedo), glm::vec3(1e-3f)))) continue;  // the same colour
      ++pairs;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(a.ratio[c] / b.ratio[c] - 1.0f));
    }
  std::printf("[ measured ] %d orange-blue pixel pairs: light over albedo differs by at most %.2f %%\n", pairs, 100.0f * worst);
  EXPECT_GT(pairs, 20);
  // 5.5 % where it works (the probes' light changes across 5 pixels near
  // the quad's edge); 825 % with the same network read as holding the albedo.
  EXPECT_LT(worst, 0.10f) << "the light over albedo should not follow the texture";
  EXPECT_GT(q.lo.g, 0.05f) << "the quad is lit by the sky";
}

// The quality path's G-buffer positions: a pixel's 16 consecutive samples (a
// still view's temporal window at one sample a frame) cover the pixel
// evenly, where 16 independent random points leave strata empty and pile
// up in others (what left thin frames grainy). The closest two of the 16
// points, on the torus, are more than 0.15 apart in every pixel (16 random
// points: 0.045 on average, 0.10 at the 99th percentile), and each quarter
// of the pixel, in x and in y, holds 2 to 6 of them. Pixels are shifted
// apart from one another (no shared pattern on screen).
TEST(GbufferSubpixel, SixteenConsecutiveSamplesStratifyEveryPixel) {
  int same_as_first_pixel = 0;
  for (std::size_t pixel = 0; pixel < 500; ++pixel)
    for (std::uint64_t first : {std::uint64_t{0}, std::uint64_t{16 * 7 + 5}}) {
      std::array<glm::vec2, 16> p;
      for (std::uint64_t k = 0; k < 16; ++k) p[k] = transgi::shading::gbuffer_subpixel(3, pixel, first + k);
      std::array<int, 4> in_x{}, in_y{};
      float closest = 2;
      for (std::size_t i = 0; i < 16; ++i) {
        ASSERT_TRUE(p[i].x >= 0 && p[i].x < 1 && p[i].y >= 0 && p[i].y < 1);
        ++in_x[static_cast<std::size_t>(p[i].x * 4)];
        ++in_y[static_cast<std::size_t>(p[i].y * 4)];
        for (std::size_t j = 0; j < i; ++j) {
          // Distance on the torus: the pattern wraps around the pixel.
          const glm::vec2 d = glm::abs(p[i] - p[j]);
          closest = std::min(closest, glm::length(glm::min(d, 1.0f - d)));
        }
      }
      for (int q = 0; q < 4; ++q) {
        EXPECT_GE(in_x[q], 2) << "pixel " << pixel;
        EXPECT_LE(in_x[q], 6) << "pixel " << pixel;
        EXPECT_GE(in_y[q], 2) << "pixel " << pixel;
        EXPECT_LE(in_y[q], 6) << "pixel " << pixel;
      }
      EXPECT_GT(closest, 0.15f) << "pixel " << pixel;
      if (pixel > 0 && transgi::shading::gbuffer_subpixel(3, pixel, 0) == transgi::shading::gbuffer_subpixel(3, 0, 0)) ++same_as_first_pixel;
    }
  EXPECT_EQ(same_as_first_pixel, 0);
}
