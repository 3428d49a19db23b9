// The probe frame loop against a known answer: probes above a large
// Lambertian floor (albedo a) under a uniform sky of radiance 1. Every ray
// down hits the floor, whose radiance is a (direct light only: an open plane
// gets no indirect light); every ray up escapes and records zero. So each
// probe's radiance is a below the horizon and 0 above, whose SH is
// L00 = a sqrt(pi) and L(1,-1) (the y coefficient) = -a 0.4886 pi.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/procedural.h"
#include "probes/probe_field.h"

using namespace transgi::probes;
using namespace engine;

namespace {
struct FloorUnderSky {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  explicit FloorUnderSky(float albedo) {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({100, 100}))};
    material::Material m;
    m.base_color_factor = glm::vec4(albedo, albedo, albedo, 1);
    m.metallic_factor = 0;
    m.specular_factor = 0;
    a.materials = {m};
    a.environment = scene::uniform_environment(glm::vec3(1.0f));
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    const ecs::Entity e = app.world().spawn();
    app.world().emplace<transform::Transform>(e);
    app.world().emplace<scene::MeshInstance>(e, scene::MeshInstance{0});
    app.update();
  }
};
}  // namespace

TEST(ProbeField, ProbesAboveALitFloorConvergeToTheAnalyticSh) {
  const float a = 0.5f;
  FloorUnderSky s(a);
  const auto& assets = s.app.world().resource<scene::SceneAssets>();
  const render::LightSet lights(s.app.world().resource<rt::RtScene>(), {}, &*assets.environment);
  ProbeFieldSettings settings;
  settings.grid = ProbeGrid{{-1, 0.5f, -1}, {1, 1.5f, 1}, {2, 2, 2}};
  settings.map = MapLayout{32, 16};
  settings.window = false;  // compare the raw projection with the analytic one
  ProbeField field(settings);
  s.app.jobs().run([&] {
    // 200 frames: with hysteresis 0.95 the history spans ~20-40 frames, and
    // 40 frames left 4 % of Monte Carlo noise in L(1,-1).
    for (int f = 0; f < 200; ++f) field.update(s.app.world().resource<rt::RtScene>(), lights);
  });
  const double pi = 3.14159265358979323846;
  for (int p = 0; p < settings.grid.count(); ++p) {
    const float* L = field.light_sh(p);
    EXPECT_NEAR(L[0], a * std::sqrt(pi), 0.04 * a * std::sqrt(pi)) << "probe " << p << " L00";
    EXPECT_NEAR(L[1], -a * 0.488603 * pi, 0.04 * a * 0.488603 * pi) << "probe " << p << " L(1,-1)";
    EXPECT_NEAR(L[25], L[0], 1e-5) << "grey: channels agree";
  }
  // The floor's irradiance from the probes (upper hemisphere sees only the
  // sky, which the probes do not hold) is near zero.
  EXPECT_LT(field.irradiance({0, 0.01f, 0}, {0, 1, 0}).g, 0.1f);
}
