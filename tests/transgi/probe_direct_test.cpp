// The probes' direct SH (the real-time path's light from the sky and from
// emissive meshes) against known answers: probes above a floor under a
// uniform sky see the upper hemisphere, and probes under a small lamp see it
// over its solid angle. Both must come out the same at every probe, not
// scattered around the answer by the few rays that happen to leave through
// an opening or hit a lamp: the scatter is what made patches a probe cell
// wide on walls (docs/image-quality.md).
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/procedural.h"
#include "floor_under_sky.h"
#include "probes/probe_field.h"
#include "probes/sky_visibility.h"
#include "shading/sh_light.h"

using namespace transgi::probes;
using namespace engine;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kY00 = 0.28209479177387814;  // 1 / (2 sqrt(pi))
constexpr double kY1 = 0.4886025119029199;    // sqrt(3 / (4 pi))

ProbeFieldSettings raw_direct_probes() {
  ProbeFieldSettings settings = floor_probe_settings();
  settings.direct_window = false;  // compare the raw projection with the analytic one
  return settings;
}

}  // namespace

TEST(SkyVisibility, ACellTakesItsFirstRayAndAveragesAnOutline) {
  SkyVisibilitySettings settings;
  settings.history_rays = 32;
  std::vector<SkyCell> cells(static_cast<std::size_t>(settings.cells.count()));
  const glm::vec3 up(0, 1, 0);
  SkyCell& c = cells[static_cast<std::size_t>(settings.cells.cell_of(up))];
  record_sky_ray(cells.data(), settings, up, true);
  EXPECT_EQ(c.escaped, 65535);
  EXPECT_EQ(c.rays, 1);
  // A window's outline: half the rays through it, alternating, average to one half.
  for (int i = 0; i < 63; ++i) record_sky_ray(cells.data(), settings, up, i % 2 == 1);
  EXPECT_NEAR(c.escaped / 65535.0, 0.5, 0.04);
  EXPECT_EQ(c.rays, 32) << "capped at history_rays";
}

TEST(SkyVisibility, ACellWhoseRaysAllAgreedRestartsWhenTheGeometryCoversIt) {
  SkyVisibilitySettings settings;
  std::vector<SkyCell> cells(static_cast<std::size_t>(settings.cells.count()));
  const glm::vec3 d = glm::normalize(glm::vec3(1, 0.3f, 0.2f));
  SkyCell& c = cells[static_cast<std::size_t>(settings.cells.cell_of(d))];
  for (int i = 0; i < 20; ++i) record_sky_ray(cells.data(), settings, d, true);
  record_sky_ray(cells.data(), settings, d, false);  // a door closed across it
  EXPECT_EQ(c.escaped, 0) << "one disagreeing ray after many agreeing restarts the cell";
  EXPECT_EQ(c.rays, 1);
  // A cell with few rays (an outline still being learnt) averages instead.
  record_sky_ray(cells.data(), settings, d, true);
  EXPECT_NEAR(c.escaped / 65535.0, 0.5, 1e-4);
  shorten_sky_history(cells.data(), settings, 1);
  EXPECT_EQ(c.rays, 1);
}

TEST(SkyVisibility, AUniformSkyProjectsToItsConstant) {
  const scene::Environment env = scene::uniform_environment(glm::vec3(2.0f, 1.0f, 0.5f));
  SkyVisibilitySettings settings;
  SkyProjection sky;
  ASSERT_TRUE(sky.refresh(&env, settings));
  EXPECT_FALSE(sky.refresh(&env, settings)) << "nothing changed";
  std::vector<SkyCell> open(static_cast<std::size_t>(settings.cells.count()), SkyCell{65535, 1, 0});
  float sh[75] = {};
  sky.add_sky_light(open.data(), sh);
  const float rgb[3] = {2.0f, 1.0f, 0.5f};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(sh[c * 25], rgb[c] * 4 * kPi * kY00, 1e-4 * rgb[c]) << "channel " << c;
    // The cells' midpoint integrals in y (the bands are polynomials in y):
    // a few 1e-5 of L00 in bands 1-3, a few 1e-4 in band 4 (which the
    // Hanning window weighs by 0.1).
    for (int k = 1; k < 25; ++k) EXPECT_NEAR(sh[c * 25 + k], 0.0f, (k < 16 ? 1e-4 : 4e-4) * sh[c * 25]) << "channel " << c << " coefficient " << k;
  }
}

// The cells' projections summed over the sphere against the whole map's
// projection (shading::project_environment, exact per texel) on a sky with
// a gradient and a bright patch smaller than a cell, turned by the map's
// matrix. (Sampling each cell at 8 x 8 points, the first version, missed
// the patch's edges by 0.5 % of L00.)
TEST(SkyVisibility, TheCellsSumToTheWholeSkysProjection) {
  image::ImageRGB map(64, 32);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x)
      map.at(x, y) = glm::vec3(0.2f + 0.8f * static_cast<float>(y) / map.height, 0.5f, 1.0f - 0.5f * static_cast<float>(x) / map.width) +
                     (x >= 40 && x < 44 && y >= 8 && y < 11 ? glm::vec3(30.0f) : glm::vec3(0.0f));
  const scene::Environment env(map, 1.5f, glm::rotate(glm::mat4(1.0f), 0.7f, glm::vec3(0.3f, 1.0f, 0.2f)));
  SkyVisibilitySettings settings;
  SkyProjection sky;
  ASSERT_TRUE(sky.refresh(&env, settings));
  std::vector<SkyCell> open(static_cast<std::size_t>(settings.cells.count()), SkyCell{65535, 1, 0});
  float cells[75] = {};
  sky.add_sky_light(open.data(), cells);
  const transgi::shading::ShRgb whole = transgi::shading::project_environment(env);
  // The same integration rule binned per cell: equal up to float rounding
  // (the cells' sums are float, then summed again).
  for (int i = 0; i < 75; ++i) EXPECT_NEAR(cells[i], whole[static_cast<std::size_t>(i)], 1e-5 * whole[(i / 25) * 25]) << "coefficient " << i;
}

TEST(SkyVisibility, TheProjectionFollowsTheMapsPixelsNotItsStorage) {
  const SkyVisibilitySettings settings;
  scene::Environment env = scene::uniform_environment(glm::vec3(1.0f));
  SkyProjection sky;
  ASSERT_TRUE(sky.refresh(&env, settings));
  // The light set rebuilds a split sun's residual into new storage on every sky edit: same pixels, no new projection.
  scene::Environment copy = env;
  EXPECT_FALSE(sky.refresh(&copy, settings));
  copy.set_strength(2.0f);
  EXPECT_TRUE(sky.refresh(&copy, settings)) << "a new strength re-lights the probes";
  const float before = sky.per_cell()[0];
  scene::Environment other = scene::uniform_environment(glm::vec3(4.0f));
  EXPECT_TRUE(sky.refresh(&other, settings));
  EXPECT_NEAR(sky.per_cell()[0], 4 * before, 1e-5f * before) << "new pixels, a new projection (at unit strength)";
}

TEST(ProbeDirect, ProbesAboveAFloorAllSeeTheUpperSkyExactly) {
  // A floor 20 km wide: the sky past its edge, within 0.01 degrees of the
  // horizon, is below the tolerance (at 100 m it was 1-2 % of L00).
  FloorUnderSky s(0.5f, nullptr, glm::vec3(0.0f), 1e4f);
  scene::Environment& env = *s.app.world().resource<scene::SceneAssets>().environment;
  const render::LightSet lights(s.app.world().resource<rt::RtScene>(), {}, &env);
  ProbeField field(raw_direct_probes());
  const auto run = [&](int frames) {
    s.app.jobs().run([&] {
      for (int f = 0; f < frames; ++f) field.update(s.app.world().resource<rt::RtScene>(), lights);
    });
  };
  // 40 frames of 100 rays: every one of the 512 cells has seen a ray (about
  // 8 each: they are of equal area); the horizon is a cell border, so each
  // cell reads exactly open or closed.
  run(40);
  const double l00 = 2 * kPi * kY00, l1y = kPi * kY1;  // upper hemisphere of radiance 1
  for (int p = 0; p < field.grid().count(); ++p) {
    const float* L = field.direct_sh_all().data() + static_cast<std::size_t>(p) * 75;
    EXPECT_NEAR(L[0], l00, 2e-3 * l00) << "probe " << p << " L00";
    EXPECT_NEAR(L[1], l1y, 2e-3 * l1y) << "probe " << p << " L(1,-1)";
    EXPECT_NEAR(L[50], L[0], 1e-6) << "grey: channels agree";
  }
  // A brighter sky re-lights every probe at once, converged (untraced) or not.
  run(200);
  int converged = 0;
  for (int p = 0; p < field.grid().count(); ++p) converged += field.state(p) == ProbeState::Converged;
  ASSERT_GT(converged, 0) << "the test wants probes that no longer trace";
  env.set_strength(3.0f);
  const render::LightSet brighter(s.app.world().resource<rt::RtScene>(), {}, &env);
  s.app.jobs().run([&] { field.update(s.app.world().resource<rt::RtScene>(), brighter); });
  for (int p = 0; p < field.grid().count(); ++p)
    EXPECT_NEAR(field.direct_sh_all()[static_cast<std::size_t>(p) * 75], 3 * l00, 6e-3 * l00) << "probe " << p;
}

TEST(ProbeDirect, ProbesUnderASmallLampSeeItOverItsSolidAngle) {
  // A lamp 0.2 m square, radiance 5, 1 m above the probes' plane; no sky.
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  const float half = 0.1f, height = 1.0f;
  const glm::vec3 radiance(5.0f, 4.0f, 3.0f);
  {
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({half, half}))};
    material::Material lamp;
    lamp.base_color_factor = glm::vec4(0, 0, 0, 1);
    lamp.emissive_factor = radiance;
    a.materials = {lamp};
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    const ecs::Entity e = app.world().spawn();
    app.world().emplace<transform::Transform>(e, transform::Transform::from_translation({0, height, 0}));
    app.world().emplace<scene::MeshInstance>(e, scene::MeshInstance{0});
    app.update();
  }
  const render::LightSet lights(app.world().resource<rt::RtScene>(), {}, nullptr);
  ASSERT_EQ(lights.emissive_triangle_count(), 2u);
  ProbeFieldSettings settings = raw_direct_probes();
  settings.grid = ProbeGrid{{-0.05f, 0.0f, -0.05f}, {0.05f, 0.0f, 0.05f}, {2, 1, 2}};  // four probes right under it
  settings.skip.classify = false;  // no surface nearby: the probes would be counted far
  ProbeField field(settings);
  const auto run = [&](const render::LightSet& set, int frames) {
    app.jobs().run([&] {
      for (int f = 0; f < frames; ++f) field.update(app.world().resource<rt::RtScene>(), set);
    });
  };
  // L00 = Le Y00 omega, omega the rectangle's solid angle from each probe, to `relative`.
  const auto expect_lamp = [&](double relative, const char* when) {
    for (int p = 0; p < field.grid().count(); ++p) {
      const glm::vec3 at = field.grid().position(p);
      double omega = 0;
      for (int i = 0; i < 4; ++i) {  // signed sum over the rectangle's corners
        const double x = (i & 1 ? half : -half) - at.x, z = (i & 2 ? half : -half) - at.z, h = height - at.y;
        omega += ((i == 0 || i == 3) ? 1 : -1) * std::atan2(x * z, h * std::sqrt(x * x + z * z + h * h));
      }
      omega = std::abs(omega);
      const float* L = field.direct_sh_all().data() + static_cast<std::size_t>(p) * 75;
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(L[c * 25], radiance[c] * kY00 * omega, relative * radiance[c] * kY00 * omega)
            << when << ": probe " << p << " channel " << c;
    }
  };
  run(lights, 64);
  expect_lamp(0.01, "64 frames");
  // Switched off (the set has no emitters), then on again: what the ECS tells
  // the field when the emissive triangles change. One update follows each.
  field.notify_scene_changed({.light_changed = true, .emitters_changed = true});
  const render::LightSet dark;
  run(dark, 1);
  for (int p = 0; p < field.grid().count(); ++p)
    EXPECT_EQ(field.direct_sh_all()[static_cast<std::size_t>(p) * 75], 0.0f) << "switched off: probe " << p;
  field.notify_scene_changed({.light_changed = true, .emitters_changed = true});
  run(lights, 1);
  expect_lamp(0.03, "one frame after it came back on");
}
