// Object-scale TransGI end to end on the committed furnace scene: a
// Lambertian sphere (albedo 0.8) under a white sky of radiance 1. A constant
// sky is exactly representable in SH, so t . L must give 0.8 with
// ground-truth transfer, and close to it with a small trained network.
#include <gtest/gtest.h>

#include "bake/trainer.h"
#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/gltf_loader.h"
#include "engine/math/sampling.h"
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
