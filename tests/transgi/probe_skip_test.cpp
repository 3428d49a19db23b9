// Skipping probe work the scene does not need (issue 5, item 9): probes
// buried in geometry or far from every surface are classified inactive and
// trace nothing; in a static scene settled probes stop updating, keep a
// correct value, and wake up when the scene changes.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/procedural.h"
#include "probes/probe_field.h"

using namespace transgi::probes;
using namespace engine;

namespace {

scene::SceneAssets grey_assets(std::vector<scene::MeshAsset> meshes, bool sky) {
  scene::SceneAssets a;
  a.generation = scene::next_scene_generation();
  for (auto& m : meshes) a.meshes.push_back(std::make_shared<scene::MeshAsset>(std::move(m)));
  material::Material m;
  m.base_color_factor = glm::vec4(0.5f, 0.5f, 0.5f, 1);
  m.metallic_factor = 0;
  m.specular_factor = 0;
  a.materials = {m};
  if (sky) a.environment = scene::uniform_environment(glm::vec3(1.0f));
  return a;
}

struct Scene {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  explicit Scene(scene::SceneAssets assets) {
    app.world().insert_resource<scene::SceneAssets>(std::move(assets));
    app.add_plugin<rt::RtPlugin>();
  }
  ecs::Entity spawn(std::uint32_t mesh, glm::vec3 at) {
    const ecs::Entity e = app.world().spawn();
    app.world().emplace<transform::Transform>(e, transform::Transform::from_translation(at));
    app.world().emplace<scene::MeshInstance>(e, scene::MeshInstance{mesh});
    return e;
  }
  const rt::RtScene& rt() { return app.world().resource<rt::RtScene>(); }
};

const char* name(ProbeState s) {
  switch (s) {
    case ProbeState::Active: return "active";
    case ProbeState::Converged: return "converged";
    case ProbeState::Buried: return "buried";
    case ProbeState::Far: return "far";
  }
  return "?";
}

}  // namespace

// A column of 4 probes at y = 0.5, 8.5, 16.5, 24.5 (cell diagonal 8) over a
// large floor, with a closed flat box (half size 4 x 1 x 4) around the second
// probe: probe 0 sees the floor at 0.5 (active), probe 1 sees only the box's
// inner faces (buried), probe 2 sees the box top at 7 (active; the box is
// wide enough for several of its 100 rays to hit), probe 3 sees nothing
// nearer than 15 (far).
TEST(ProbeSkip, BuriedAndFarProbesAreClassifiedAndSkipped) {
  Scene s(grey_assets({scene::make_quad({100, 100}), scene::make_box(glm::vec3(4, 1, 4))}, true));
  s.spawn(0, {0, 0, 0});
  const ecs::Entity box = s.spawn(1, {0, 8.5f, 0});
  s.app.update();
  const auto& assets = s.app.world().resource<scene::SceneAssets>();
  const render::LightSet lights(s.rt(), {}, &*assets.environment);
  ProbeFieldSettings settings;
  settings.grid = ProbeGrid{{0, 0.5f, 0}, {0, 24.5f, 0}, {1, 4, 1}};
  settings.map = MapLayout{16, 8};
  ProbeField field(settings);
  ProbeFrameStats first, second;
  s.app.jobs().run([&] {
    first = field.update(s.rt(), lights);
    second = field.update(s.rt(), lights);
  });
  const ProbeState expected[4] = {ProbeState::Active, ProbeState::Buried, ProbeState::Active, ProbeState::Far};
  for (int q = 0; q < 4; ++q) EXPECT_EQ(field.state(q), expected[q]) << "probe " << q << ": got " << name(field.state(q));
  EXPECT_TRUE(first.classified);
  EXPECT_EQ(first.traced, 4) << "the classification frame traces every probe";
  EXPECT_EQ(second.traced, 2) << "then only the active ones";
  EXPECT_EQ(second.rays, 2u * static_cast<std::size_t>(settings.rays_per_probe));
  for (int k = 0; k < 75; ++k) EXPECT_EQ(field.light_sh(1)[k], 0.0f) << "a buried probe holds no light";

  // A point between the floor probe and the buried one is lit by the floor
  // probe only: the buried probe gets no weight.
  const InterpolationResult r =
      interpolate_probes(settings.grid, settings.map, field.states(), {0, 4.0f, 0}, {0, 1, 0}, settings.interpolation,
                         std::vector<std::uint8_t>{1, 0, 1, 0});
  EXPECT_FLOAT_EQ(r.weights[0] + r.weights[1] + r.weights[2] + r.weights[3] + r.weights[4] + r.weights[5] + r.weights[6] +
                      r.weights[7],
                  1.0f);
  for (std::size_t i = 0; i < 8; ++i)
    if (r.probes[i] == 1) {
      EXPECT_EQ(r.weights[i], 0.0f) << "cage slot " << i << " is the buried probe";
    }

  // Move the box away: after the geometry change the probes are classified
  // again; both now see only the floor, 8.5 and 16.5 away (beyond 8): far.
  s.app.world().get_mut<transform::Transform>(box).translation = {50, 8.5f, 50};
  s.app.update();
  field.notify_scene_changed({.geometry_moved = true});
  ProbeFrameStats third;
  s.app.jobs().run([&] { third = field.update(s.rt(), lights); });
  EXPECT_TRUE(third.classified);
  EXPECT_EQ(field.state(1), ProbeState::Far) << "got " << name(field.state(1)) << ": no longer buried, the floor is 8.5 away";
  EXPECT_EQ(field.state(2), ProbeState::Far) << "got " << name(field.state(2)) << ": nothing within 8 any more";
  EXPECT_EQ(field.state(0), ProbeState::Active) << "got " << name(field.state(0));
}

// In a static scene probes settle, stop tracing, and still hold the analytic
// answer of the lit-floor known-answer test (probe_field_test.cpp): L00 =
// a sqrt(pi) for radiance a below the horizon. A scene change wakes them.
TEST(ProbeSkip, ConvergedProbesStopUpdatingAndWakeOnChange) {
  const float a = 0.5f;
  Scene s(grey_assets({scene::make_quad({100, 100})}, true));
  s.spawn(0, {0, 0, 0});
  s.app.update();
  const auto& assets = s.app.world().resource<scene::SceneAssets>();
  const render::LightSet lights(s.rt(), {}, &*assets.environment);
  ProbeFieldSettings settings;
  settings.grid = ProbeGrid{{-1, 0.5f, -1}, {1, 1.5f, 1}, {2, 2, 2}};
  settings.map = MapLayout{32, 16};
  settings.skip.settle_frames = 48;
  ProbeField field(settings);
  int first_all_converged = -1, traced_after = -1;
  s.app.jobs().run([&] {
    for (int f = 0; f < 200; ++f) {
      const ProbeFrameStats st = field.update(s.rt(), lights);
      if (first_all_converged < 0 && st.converged == settings.grid.count()) first_all_converged = f;
      if (f == 199) traced_after = st.traced;
    }
  });
  std::printf("all probes converged after frame %d (warm-up %d + settle %d)\n", first_all_converged,
              settings.accumulation.warmup_frames, settings.skip.settle_frames);
  ASSERT_GE(first_all_converged, settings.accumulation.warmup_frames + settings.skip.settle_frames - 1);
  EXPECT_LT(first_all_converged, 150) << "the noise must not keep triggering the change detector";
  EXPECT_EQ(traced_after, 0) << "converged probes trace nothing";
  const double expected = a * std::sqrt(3.14159265358979323846);
  for (int p = 0; p < settings.grid.count(); ++p)
    EXPECT_NEAR(field.light_sh(p)[0], expected, 0.04 * expected) << "probe " << p << " froze a wrong L00";

  field.notify_scene_changed({.light_changed = true});
  ProbeFrameStats woken;
  s.app.jobs().run([&] { woken = field.update(s.rt(), lights); });
  EXPECT_EQ(woken.traced, settings.grid.count()) << "a scene change wakes every converged probe";
  EXPECT_FALSE(woken.classified) << "a lighting change alone does not reclassify";
}
