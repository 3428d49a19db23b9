// The committed scenes load, have what their description promises, and the
// furnace scene gives its analytic answer end to end (glTF + EXR sky +
// environment importance sampling + path tracer).
#include <gtest/gtest.h>

#include <set>

#include "engine/app/app.h"
#include "engine/jobs/job_system.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_assets.h"

using namespace engine;

namespace {
const std::string kContent = TRANSGI_CONTENT_DIR;

struct Loaded {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  scene::GltfLoadResult result;
  explicit Loaded(const std::string& rel) {
    app.add_plugin<rt::RtPlugin>();
    result = scene::load_gltf(app.world(), kContent + "/" + rel);
    app.update();
  }
  const scene::SceneAssets& assets() { return app.world().resource<scene::SceneAssets>(); }
  ecs::Entity camera() {
    for (ecs::Entity e : result.entities)
      if (app.world().has<scene::Camera>(e)) return e;
    return {};
  }
  render::LightSet lights() {
    return render::LightSet(app.world().resource<rt::RtScene>(), render::gather_punctual_lights(app.world()),
                            assets().environment ? &*assets().environment : nullptr);
  }
};
}  // namespace

TEST(Content, CornellBox) {
  Loaded s("test_scenes/cornell_box/scene.gltf");
  EXPECT_FALSE(s.camera().is_null());
  EXPECT_EQ(s.lights().emissive_triangle_count(), 2u) << "one emissive quad";
  EXPECT_FALSE(s.assets().environment.has_value());
}

TEST(Content, SampleLevelHasEverythingTheLevelPromises) {
  Loaded s("levels/living_room/scene.gltf");
  EXPECT_FALSE(s.camera().is_null());
  ASSERT_TRUE(s.assets().environment.has_value()) << "the window is lit by a sky map";
  EXPECT_GT(s.lights().emissive_triangle_count(), 0u) << "and by an area light";
  bool glossy_metal = false, mirror = false, rough_plastic = false;
  for (const auto& m : s.assets().materials) {
    glossy_metal |= m.metallic_factor == 1.0f && m.roughness_factor > 0.1f && m.roughness_factor < 0.5f;
    mirror |= m.metallic_factor == 1.0f && m.roughness_factor < 0.05f;
    rough_plastic |= m.metallic_factor == 0.0f && m.specular_factor > 0.0f && m.roughness_factor >= 0.3f;
  }
  EXPECT_TRUE(glossy_metal);
  EXPECT_TRUE(mirror);
  EXPECT_TRUE(rough_plastic);
  std::multiset<std::uint32_t> mesh_uses;
  s.app.world().view<const scene::MeshInstance>().each([&](const scene::MeshInstance& m) { mesh_uses.insert(m.mesh); });
  bool shared = false;
  for (std::uint32_t m : mesh_uses) shared |= mesh_uses.count(m) > 1;
  EXPECT_TRUE(shared) << "the table legs share one mesh asset";
}

TEST(Content, FurnaceSceneGivesAlbedoTimesSky) {
  // Sphere albedo 0.8 (Lambert) under a white sky of radiance 1: L = 0.8.
  Loaded s("test_scenes/furnace/scene.gltf");
  const auto lights = s.lights();
  auto& w = s.app.world();
  const render::CameraRays cam(w.get<scene::Camera>(s.camera()), w.get<transform::WorldTransform>(s.camera()), 32, 32);
  render::PathTracer pt(w.resource<rt::RtScene>(), lights, cam, 32, 32);
  s.app.jobs().run([&] { pt.render(64); });
  const auto img = pt.image(render::Pass::Full);
  double sum = 0;
  for (int y = 12; y < 20; ++y)
    for (int x = 12; x < 20; ++x) sum += img.at(x, y).g;
  EXPECT_NEAR(sum / 64, 0.8, 0.016) << "expected 0.8";
  EXPECT_NEAR(img.at(0, 0).g, 1.0f, 1e-3f) << "the sky itself";
}
