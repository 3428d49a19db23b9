// Probe updates within a per-frame budget (issue 10, item 5): at most the
// budget traces per frame, every active probe is refreshed round-robin, and
// the budgeted field still converges to the floor's analytic SH.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/render/light_set.h"
#include "floor_under_sky.h"
#include "probes/probe_field.h"

using namespace transgi::probes;
using namespace engine;

namespace {
// The floor under a uniform sky with 32 probes above it (4x2x4, none far
// from the floor), small maps: the setting every budget test starts from.
struct BudgetFloor {
  FloorUnderSky scene;
  render::LightSet lights;
  explicit BudgetFloor(float albedo)
      : scene(albedo), lights(rt(), {}, &*scene.app.world().resource<scene::SceneAssets>().environment) {}
  const rt::RtScene& rt() { return scene.app.world().resource<rt::RtScene>(); }
  static ProbeFieldSettings settings() {
    ProbeFieldSettings s;
    s.grid = ProbeGrid{{-1, 0.5f, -1}, {1, 1.0f, 1}, {4, 2, 4}};
    s.map = MapLayout{32, 16};
    return s;
  }
};
}  // namespace

TEST(ProbeBudget, TracesAtMostTheBudgetAndRefreshesEveryProbeInTurn) {
  const float a = 0.5f;
  BudgetFloor floor(a);
  FloorUnderSky& s = floor.scene;
  const auto& rt = floor.rt();
  const render::LightSet& lights = floor.lights;
  ProbeFieldSettings settings = floor.settings();
  settings.skip.skip_converged = false;
  settings.update_budget = 5;
  ProbeField field(settings);
  std::vector<int> updates(32, 0);
  s.app.jobs().run([&] {
    field.update(rt, lights);  // the first frame classifies every probe
    for (int f = 1; f < 640; ++f) {
      const ProbeFrameStats st = field.update(rt, lights);
      ASSERT_LE(st.traced, 5) << "frame " << f;
      ASSERT_EQ(st.traced, 5) << "frame " << f << ": 32 active probes, the budget must be spent";
      if (f == 320) field.notify_scene_changed({.geometry_moved = true});  // queues classification, still within budget
    }
  });
  // 639 frames x 5 = 3195 updates over 32 probes: round-robin gives each
  // 99 or 100; the analytic answer holds for every one.
  const double pi = 3.14159265358979323846;
  for (int p = 0; p < 32; ++p) {
    const float* L = field.light_sh(p);
    EXPECT_NEAR(L[0], a * std::sqrt(pi), 0.04 * a * std::sqrt(pi)) << "probe " << p << " L00";
    EXPECT_NEAR(L[1], -a * 0.488603 * pi, 0.05 * a * 0.488603 * pi) << "probe " << p << " L(1,-1)";
  }
}

TEST(ProbeBudget, ZeroBudgetUpdatesEveryActiveProbe) {
  BudgetFloor floor(0.5f);
  FloorUnderSky& s = floor.scene;
  const auto& rt = floor.rt();
  const render::LightSet& lights = floor.lights;
  ProbeFieldSettings settings = floor.settings();
  ProbeField field(settings);
  s.app.jobs().run([&] {
    for (int f = 0; f < 3; ++f) EXPECT_EQ(field.update(rt, lights).traced, 32);
  });
}

TEST(ProbeBudget, AChangedRegionIsUpdatedFirst) {
  // 32 probes, budget 5: round-robin alone reaches a probe every 6-7
  // frames. A change at one corner probe marks the 8 probes within a cell of
  // it: the next two frames must trace exactly those, before any other.
  BudgetFloor floor(0.5f);
  FloorUnderSky& s = floor.scene;
  const auto& rt = floor.rt();
  const render::LightSet& lights = floor.lights;
  ProbeFieldSettings settings = floor.settings();
  settings.skip.skip_converged = false;
  settings.update_budget = 5;
  ProbeField field(settings);
  const ProbeGrid& g = settings.grid;
  auto near_corner = [&](int q) {
    const glm::ivec3 c(q % 4, q / 4 % 2, q / 8);
    return c.x >= 2 && c.z >= 2;  // within one cell of (3, *, 3); y spans both layers
  };
  s.app.jobs().run([&] {
    for (int f = 0; f < 13; ++f) field.update(rt, lights);
    const glm::vec3 p = g.position(g.index({3, 1, 3}));
    field.notify_region_changed(p - glm::vec3(0.01f), p + glm::vec3(0.01f));
    const std::uint64_t first = field.frame();
    field.update(rt, lights);
    field.update(rt, lights);
    int traced_near = 0;
    for (int q = 0; q < g.count(); ++q) {
      const bool traced = field.last_traced(q) >= first;
      if (near_corner(q)) {
        EXPECT_TRUE(traced) << "probe " << q << " lies within a cell of the change and was not traced in 2 frames";
        traced_near += traced;
      } else if (traced) {
        // 8 urgent probes, 10 budget slots: 2 go to the stalest others.
        EXPECT_LT(field.last_traced(q), first + 2) << "probe " << q;
      }
    }
    EXPECT_EQ(traced_near, 8);
    // The first frame spends its whole budget on the region.
  });
}

// settle_frames: the field's first updates trace every active probe, as a
// loading screen would, then the budget holds. After the 3 settling frames
// the SH equal those of a field with no budget after 3 frames (the same
// probes traced the same rays), so the settling is a full update.
TEST(ProbeBudget, SettlingFramesTraceEveryProbeThenTheBudgetHolds) {
  BudgetFloor floor(0.5f);
  ProbeFieldSettings settings = floor.settings();
  settings.skip.skip_converged = false;
  ProbeField unbudgeted(settings);  // no budget
  settings.update_budget = 5;
  settings.settle_frames = 3;
  ProbeField settled(settings);
  floor.scene.app.jobs().run([&] {
    for (int f = 0; f < 3; ++f) {
      EXPECT_EQ(settled.update(floor.rt(), floor.lights).traced, 32) << "settling frame " << f;
      unbudgeted.update(floor.rt(), floor.lights);
    }
  });
  for (int p = 0; p < 32; ++p)
    for (int k = 0; k < 75; ++k)
      ASSERT_EQ(settled.light_sh(p)[k], unbudgeted.light_sh(p)[k]) << "probe " << p << " value " << k;
  floor.scene.app.jobs().run([&] {
    for (int f = 3; f < 8; ++f) EXPECT_EQ(settled.update(floor.rt(), floor.lights).traced, 5) << "frame " << f << " is past the settling";
  });
}

// steady_light_budget: while the lights hold, a field spends the smaller
// budget; a light change gives the full budget back at once, for
// skip.settle_frames frames; a moved object alone does not.
TEST(ProbeBudget, TheFullBudgetReturnsWhileALightChangesAndForItsSettling) {
  BudgetFloor floor(0.5f);
  ProbeFieldSettings settings = floor.settings();
  settings.skip.skip_converged = false;
  settings.skip.settle_frames = 6;
  settings.update_budget = 8;
  settings.steady_light_budget = 3;
  ProbeField field(settings);
  std::vector<int> traced;
  floor.scene.app.jobs().run([&] {
    field.update(floor.rt(), floor.lights);  // the first frame classifies every probe
    for (int f = 1; f < 30; ++f) {
      if (f == 10) field.notify_scene_changed({.geometry_moved = true});
      if (f == 15) field.notify_scene_changed({.light_changed = true});
      traced.push_back(field.update(floor.rt(), floor.lights).traced);
    }
  });
  // traced[i] is frame i + 1's. Frame 10 classifies (every probe traces).
  for (int f = 1; f < 30; ++f) {
    const int got = traced[static_cast<std::size_t>(f - 1)];
    if (f == 10) continue;
    const int want = f >= 15 && f < 15 + 6 ? 8 : 3;
    EXPECT_EQ(got, want) << "frame " << f << (want == 8 ? ": a light changed at frame 15" : ": the lights hold");
  }
}
