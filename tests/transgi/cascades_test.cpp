// Camera-centred probe cascades (issue 16): toroidal addressing that keeps
// each probe's data attached to its world position, blend weights that sum
// to one, an authored volume that overrides the cascades inside it, and a
// camera that crosses cell boundaries without a black or non-finite pixel.
#include <gtest/gtest.h>

#include "lambert.h"

#include <cmath>

#include <glm/gtc/quaternion.hpp>

#include "ddgi/ddgi_plugin.h"
#include "engine/app/app.h"
#include "engine/math/rng.h"
#include "engine/render/light_plugin.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/procedural.h"
#include "probes/cascades.h"
#include "engine/scene/gltf_loader.h"
#include "runtime/probe_placement.h"
#include "runtime/probe_sync.h"
#include "runtime/transgi_plugin.h"

using namespace transgi;
using namespace transgi::probes;
using namespace engine;

namespace {

glm::ivec3 random_cells(math::Pcg32& rng, int reach) {
  const auto one = [&] { return static_cast<int>(rng.next_u32() % static_cast<std::uint32_t>(2 * reach + 1)) - reach; };
  return {one(), one(), one()};
}

bool inside(const ProbeGrid& g, const glm::vec3& p) {
  const glm::vec3 tol = 1e-3f * g.spacing();
  return glm::all(glm::greaterThanEqual(p, g.min - tol)) && glm::all(glm::lessThanEqual(p, g.max + tol));
}

}  // namespace

TEST(ToroidalGrid, EveryStorageIndexKeepsItsWorldPointForAnyWholeCellScroll) {
  ProbeGrid g{{-2.0f, 0.5f, 1.0f}, {2.0f, 1.5f, 4.0f}, {5, 3, 4}};
  const glm::vec3 spacing = g.spacing();
  math::Pcg32 rng = math::make_rng(16, 1, 0);
  for (int step = 0; step < 200; ++step) {
    // Mostly small moves (a walking camera), sometimes a teleport past the grid.
    const glm::ivec3 cells = random_cells(rng, step % 10 == 9 ? 9 : 2);
    const ProbeGrid before = g;
    g.scroll_by(cells);
    EXPECT_EQ(g.spacing(), spacing);
    for (int i = 0; i < g.count(); ++i) {
      ASSERT_EQ(g.index(g.coords(i)), i) << "storage " << i << " after scroll (" << cells.x << "," << cells.y << "," << cells.z << ")";
      const glm::vec3 was = before.grid_point(i), now = g.grid_point(i);
      const bool entered = g.entered_by_scroll(i, cells);
      // Entered exactly when its new world point was outside the old grid.
      EXPECT_EQ(entered, !inside(before, now)) << "storage " << i << " at step " << step;
      if (!entered) {
        // Kept: the same world point, to float rounding of min + c x spacing.
        EXPECT_NEAR(now.x, was.x, 1e-4f) << "storage " << i << " at step " << step;
        EXPECT_NEAR(now.y, was.y, 1e-4f) << "storage " << i << " at step " << step;
        EXPECT_NEAR(now.z, was.z, 1e-4f) << "storage " << i << " at step " << step;
      }
    }
  }
}

TEST(ToroidalGrid, ZeroScrollIsTheRowMajorLayout) {
  const ProbeGrid g{{0, 0, 0}, {1, 1, 1}, {3, 4, 5}};
  for (int i = 0; i < g.count(); ++i) {
    const glm::ivec3 c = g.coords(i);
    EXPECT_EQ((c.z * 4 + c.y) * 3 + c.x, i);
  }
}

// The fast cage (per axis once, then combined) gives the reference's probes,
// weights and positions bit for bit: scrolled and unscrolled grids, one-probe
// axes, relocated probes, points inside and outside the box.
TEST(ToroidalGrid, TheFastCageEqualsTheReference) {
  engine::math::Pcg32 rng = engine::math::make_rng(11, 0, 0);
  int checked = 0;
  for (const glm::ivec3 dims : {glm::ivec3(8), glm::ivec3(4, 1, 6), glm::ivec3(1), glm::ivec3(2, 3, 16)}) {
    ProbeGrid g{glm::vec3(-3.0f, 0.1f, -2.0f), glm::vec3(5.0f, 3.3f, 7.5f), dims};
    for (int trial = 0; trial < 3; ++trial) {
      if (trial == 1) g.scroll_by(glm::ivec3(3, 1, -5));
      if (trial == 2) {
        g.offsets.resize(static_cast<std::size_t>(g.count()));
        for (auto& o : g.offsets) o = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 0.2f - 0.1f;
      }
      for (int i = 0; i < 500; ++i) {
        const glm::vec3 p = glm::mix(g.min - 2.0f, g.max + 2.0f, glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()));
        const ProbeGrid::Cage fast = g.cage(p), ref = g.cage_reference(p);
        for (std::size_t k = 0; k < 8; ++k) {
          ASSERT_EQ(fast.probes[k], ref.probes[k]) << "corner " << k << " of point " << i << ", dims " << dims.x << "x" << dims.y << "x" << dims.z;
          ASSERT_EQ(fast.weights[k], ref.weights[k]) << "corner " << k << " of point " << i;
          ASSERT_EQ(fast.positions[k], ref.positions[k]) << "corner " << k << " of point " << i;
        }
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 6000);
}

TEST(CascadePlacement, CellsDoubleAndTheCameraSitsInTheMiddleCell) {
  CascadeSettings s;
  s.finest_cell = 0.5f;
  const glm::vec3 eye{3.3f, 1.7f, -12.1f};
  for (int k = 0; k < s.count; ++k) {
    const ProbeGrid g = cascade_grid(s, k, cascade_origin(s, k, eye));
    const float cell = 0.5f * static_cast<float>(1 << k);
    EXPECT_NEAR(g.spacing().x, cell, 1e-5f) << "cascade " << k;
    // The eye lies within half a cell of probe dims/2 on each axis.
    for (int a = 0; a < 3; ++a) {
      const float middle = g.min[a] + static_cast<float>(s.dims[a] / 2) * cell;
      EXPECT_LE(std::abs(eye[a] - middle), 0.5f * cell + 1e-4f) << "cascade " << k << " axis " << a;
    }
    // Probes at cell centres: none on a plane through the origin (y = 0).
    const float f = g.min.y / cell - std::floor(g.min.y / cell);
    EXPECT_NEAR(f, 0.5f, 1e-4f) << "cascade " << k;
  }
}

TEST(CascadeBlend, WeightsSumToOneAndTheFinestHoldsItsInterior) {
  CascadeSettings s;
  const glm::vec3 eye{0.3f, 1.6f, -0.2f};
  std::vector<BlendBox> boxes;
  for (int k = 0; k < s.count; ++k) {
    const ProbeGrid g = cascade_grid(s, k, cascade_origin(s, k, eye));
    boxes.push_back({g.min, g.max, s.blend_cells * g.min_spacing()});
  }
  math::Pcg32 rng = math::make_rng(16, 2, 0);
  int blended = 0;
  for (int i = 0; i < 20000; ++i) {
    const glm::vec3 p = eye + 40.0f * (glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) - 0.5f);
    const BoxMix m = blend_boxes(boxes, p);
    const float sum = m.weight[0] + (m.count > 1 ? m.weight[1] : 0.0f);
    ASSERT_NEAR(sum, 1.0f, 1e-6f) << "at (" << p.x << "," << p.y << "," << p.z << ")";
    for (int j = 0; j < m.count; ++j) {
      ASSERT_GE(m.weight[static_cast<std::size_t>(j)], 0.0f);
      ASSERT_LE(m.weight[static_cast<std::size_t>(j)], 1.0f);
    }
    if (m.count == 2) {
      ++blended;
      EXPECT_LT(m.box[0], m.box[1]) << "hands over to a coarser cascade";
    }
  }
  EXPECT_GT(blended, 100) << "the bands were never crossed: the test sampled nothing";
  // Deep inside the finest cascade: all of it, from the finest.
  const BoxMix centre = blend_boxes(boxes, eye);
  EXPECT_EQ(centre.count, 1);
  EXPECT_EQ(centre.box[0], 0);
  // Halfway through the finest cascade's band: half and half with the next.
  const float band = boxes[0].band;
  const glm::vec3 half_band{boxes[0].hi.x - 0.5f * band, eye.y, eye.z};
  const BoxMix mid = blend_boxes(boxes, half_band);
  ASSERT_EQ(mid.count, 2);
  EXPECT_EQ(mid.box[1], 1);
  EXPECT_NEAR(mid.weight[0], 0.5f, 1e-4f);
  // Outside every box: the coarsest, clamped.
  const BoxMix far = blend_boxes(boxes, eye + glm::vec3(1e4f));
  EXPECT_EQ(far.count, 1);
  EXPECT_EQ(far.box[0], s.count - 1);
}

TEST(CascadeBlend, AFallbackBoxLightsOnlyWhatNoOtherBoxHolds) {
  // One cascade [0, 10]^3 with a 2 m band, then a far field [-100, 100]^3:
  // inside the cascade, the blend is what it was without the far field (the
  // band keeps its light whole); beyond it, the far field takes all.
  const std::vector<BlendBox> alone = {{glm::vec3(0.0f), glm::vec3(10.0f), 2.0f}};
  std::vector<BlendBox> with = alone;
  with.push_back({glm::vec3(-100.0f), glm::vec3(100.0f), 0.0f, true});
  for (const glm::vec3 p : {glm::vec3(5.0f), glm::vec3(9.5f, 5.0f, 5.0f), glm::vec3(0.2f, 0.1f, 9.9f)}) {
    const BoxMix a = blend_boxes(alone, p), b = blend_boxes(with, p);
    EXPECT_EQ(b.count, a.count);
    EXPECT_EQ(b.box[0], 0);
    EXPECT_EQ(b.weight[0], a.weight[0]) << "at (" << p.x << ", " << p.y << ", " << p.z << ")";
  }
  const BoxMix beyond = blend_boxes(with, glm::vec3(50.0f, 5.0f, 5.0f));
  EXPECT_EQ(beyond.count, 1);
  EXPECT_EQ(beyond.box[0], 1);
  EXPECT_EQ(beyond.weight[0], 1.0f);
  EXPECT_EQ(blend_boxes(with, glm::vec3(500.0f)).box[0], 1) << "outside every box: the fallback, clamped";
}

TEST(CascadeBlend, AnAuthoredVolumeOverridesTheCascadesInsideIt) {
  CascadeSettings s;
  const glm::vec3 eye{0.0f, 1.5f, 0.0f};
  std::vector<BlendBox> boxes;
  // The authored volume first (a 6 m room, bands of one of its 0.75 m cells), then the cascades.
  boxes.push_back({{-3.0f, 0.0f, -3.0f}, {3.0f, 3.0f, 3.0f}, 0.75f});
  for (int k = 0; k < s.count; ++k) {
    const ProbeGrid g = cascade_grid(s, k, cascade_origin(s, k, eye));
    boxes.push_back({g.min, g.max, s.blend_cells * g.min_spacing()});
  }
  for (const glm::vec3 p : {glm::vec3(0.0f, 1.5f, 0.0f), glm::vec3(1.9f, 0.8f, -2.2f), glm::vec3(-2.2f, 2.2f, 2.2f)}) {
    const BoxMix m = blend_boxes(boxes, p);
    EXPECT_EQ(m.count, 1) << "at (" << p.x << "," << p.y << "," << p.z << ")";
    EXPECT_EQ(m.box[0], 0) << "at (" << p.x << "," << p.y << "," << p.z << ")";
  }
  // Past its faces, the cascades take over.
  const BoxMix out = blend_boxes(boxes, glm::vec3(3.4f, 1.5f, 0.0f));
  EXPECT_GT(out.box[0], 0);
}

namespace {

// A closed 12 x 4 x 12 m room lit by one point light, with a box in it: every
// surface the camera sees gets indirect light. No model: every pixel is
// shaded diffusely from the probes, so each pixel's GI is the cascades' alone.
struct Room {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity camera;

  // ground_half > 0: the room stands on a flat ground plane that far each way.
  explicit Room(const CascadeSettings& cascades, bool ddgi = false, float ground_half = 0.0f) {
    auto& w = app.world();
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_box({6.0f, 2.0f, 6.0f}, true, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_box(glm::vec3(0.6f), false, 1)),
                std::make_shared<scene::MeshAsset>(scene::make_quad(glm::vec2(std::max(ground_half, 1.0f)), 0))};
    a.materials = {lambert(glm::vec3(0.6f)), lambert({0.8f, 0.4f, 0.2f})};
    w.insert_resource<scene::SceneAssets>(std::move(a));
    if (ddgi) {
      ddgi::DdgiSettings d;
      d.rays_per_probe = 64;
      d.warmup_frames = 16;
      app.add_plugin<ddgi::DdgiPlugin>(d, ddgi::DdgiRenderOptions{.direct_spp = 0});
    } else {
      runtime::TransGISettings s = runtime::realtime_preset();
      s.probes.map = MapLayout{16, 8};
      s.probes.update_budget = 64;
      s.direct_spp = 0;
      app.add_plugin<runtime::TransGIPlugin>(s);
    }
    const ecs::Entity room = w.spawn();
    w.emplace<transform::Transform>(room, transform::Transform::from_translation({0.0f, 2.0f, 0.0f}));
    w.emplace<scene::MeshInstance>(room, scene::MeshInstance{0});
    const ecs::Entity box = w.spawn();
    w.emplace<transform::Transform>(box, transform::Transform::from_translation({1.5f, 0.6f, -2.0f}));
    w.emplace<scene::MeshInstance>(box, scene::MeshInstance{1});
    if (ground_half > 0) {
      const ecs::Entity ground = w.spawn();
      w.emplace<transform::Transform>(ground, transform::Transform::from_translation({0.0f, -0.001f, 0.0f}));
      w.emplace<scene::MeshInstance>(ground, scene::MeshInstance{2});
    }
    const ecs::Entity lamp = w.spawn();
    w.emplace<transform::Transform>(lamp, transform::Transform::from_translation({-2.0f, 3.2f, 1.0f}));
    w.emplace<scene::PunctualLight>(lamp, scene::PunctualLight{.type = scene::PunctualLight::Type::Point, .intensity = 40.0f});
    camera = w.spawn();
    w.emplace<transform::Transform>(camera, pose(0.0f));
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 1.0f});
    if (ddgi)
      w.emplace<ddgi::DdgiCascades>(w.spawn(), ddgi::DdgiCascades{.cascades = cascades});
    else
      w.emplace<runtime::ProbeCascades>(w.spawn(), runtime::ProbeCascades{.cascades = cascades});
  }
  static transform::Transform pose(float x) {
    transform::Transform t = transform::Transform::from_translation({x, 1.7f, 3.0f});
    t.rotation = glm::quatLookAtRH(glm::normalize(glm::vec3(0.3f, -0.35f, -1.0f)), glm::vec3(0, 1, 0));
    return t;
  }
  runtime::GiFrame& frame() { return app.world().resource<runtime::GiFrame>(); }
};

}  // namespace

TEST(CascadeScroll, ACameraCrossingCellsNeverGivesABlackOrNonFinitePixel) {
  CascadeSettings cs;
  cs.count = 3;
  cs.finest_cell = 0.5f;
  cs.dims = glm::ivec3(6);
  cs.fit_scene_cell = 0.0f;  // always cascades, small as the room is
  Room room(cs);
  auto& frame = room.frame();
  frame.width = 48;
  frame.height = 27;
  // Warm up at rest, then walk 4 m sideways in 0.13 m steps: the finest
  // cascade crosses a cell every 4 frames or so, the others less often.
  for (int f = 0; f < 48; ++f) room.app.jobs().run([&] { room.app.update(); });
  int crossings = 0, entered = 0;
  for (int f = 0; f < 31; ++f) {
    room.app.world().get_mut<transform::Transform>(room.camera) = Room::pose(0.13f * static_cast<float>(f + 1));
    room.app.jobs().run([&] { room.app.update(); });
    crossings += frame.cascade_probes_entered > 0;
    entered += frame.cascade_probes_entered;
    int black = 0, nonfinite = 0;
    for (const glm::vec3& p : frame.gi.pixels) {
      if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b)) ++nonfinite;
      else if (p.r <= 0.0f && p.g <= 0.0f && p.b <= 0.0f) ++black;
    }
    ASSERT_EQ(nonfinite, 0) << "frame " << f;
    ASSERT_EQ(black, 0) << "frame " << f << ": black GI pixels right after " << frame.cascade_probes_entered << " probes entered";
  }
  EXPECT_GE(crossings, 6) << "the walk crossed too few cells to test scrolling";
  EXPECT_GT(entered, 0);
  ASSERT_EQ(frame.cascade_stats.size(), 3u);
}

TEST(CascadeScroll, ProbesThatStayKeepTheirLightAndEnteredOnesAreSeededFromTheCoarser) {
  CascadeSettings cs;
  cs.count = 2;
  cs.dims = glm::ivec3(6);
  cs.fit_scene_cell = 0.0f;
  Room room(cs);
  for (int f = 0; f < 24; ++f) room.app.jobs().run([&] { room.app.update(); });
  runtime::ProbeCascades* set = nullptr;
  room.app.world().view<runtime::ProbeCascades>().each([&](runtime::ProbeCascades& c) { set = &c; });
  ASSERT_NE(set, nullptr);
  ProbeField& fine = *set->state.fields[0];
  const ProbeField& coarse = *set->state.fields[1];
  std::vector<float> before(fine.light_sh_all());
  const ProbeGrid grid_before = fine.grid();
  const glm::ivec3 cells{1, 0, -2};
  const int entered = fine.scroll(cells, &coarse);
  EXPECT_EQ(entered, 6 * 6 * 6 - 5 * 6 * 4) << "a (1, 0, -2) scroll of a 6^3 grid";
  int kept = 0, seeded = 0;
  for (int q = 0; q < fine.grid().count(); ++q) {
    const float* now = fine.light_sh(q);
    if (!fine.grid().entered_by_scroll(q, cells)) {
      ++kept;
      ASSERT_NEAR(glm::length(fine.grid().grid_point(q) - grid_before.grid_point(q)), 0.0f, 1e-4f);
      for (int k = 0; k < 75; ++k) ASSERT_EQ(now[k], before[static_cast<std::size_t>(q) * 75 + k]) << "probe " << q << " coefficient " << k;
    } else {
      float expect[75], expect_direct[75];
      coarse.light_at_point(fine.grid().grid_point(q), expect, expect_direct);
      for (int k = 0; k < 75; ++k) ASSERT_EQ(now[k], expect[k]) << "entered probe " << q << " coefficient " << k;
      seeded += expect[0] > 0.0f;
    }
  }
  EXPECT_EQ(kept, 5 * 6 * 4);
  EXPECT_GT(seeded, 0) << "no entered probe got light from the coarser cascade";
}

namespace {
// One frame of the room; its cascade set as the plugin left it.
const runtime::ProbeCascades* first_frames_cascades(Room& room) {
  room.app.jobs().run([&] { room.app.update(); });
  const runtime::ProbeCascades* set = nullptr;
  room.app.world().view<const runtime::ProbeCascades>().each([&](const runtime::ProbeCascades& c) { set = &c; });
  return set;
}
}  // namespace

TEST(CascadeFit, ASmallSceneGetsOneGridOverItsBoundsAndABigOneGetsCascades) {
  for (const float fit : {2.5f, 1.0f}) {
    CascadeSettings cs;
    cs.dims = glm::ivec3(6);
    cs.fit_scene_cell = fit;  // the room is 12 m: 2 m cells over its bounds
    Room room(cs);
    const runtime::ProbeCascades* set = first_frames_cascades(room);
    ASSERT_NE(set, nullptr);
    const auto& rt = room.app.world().resource<rt::RtScene>();
    if (fit >= 2.0f) {
      ASSERT_EQ(set->state.fields.size(), 1u) << "fit_scene_cell " << fit;
      EXPECT_TRUE(set->state.fitted_to_scene);
      const ProbeGrid expect = ProbeGrid::centred_in(rt.bounds_min(), rt.bounds_max(), cs.dims);
      EXPECT_EQ(set->state.fields[0]->settings().grid, expect);
    } else {
      EXPECT_EQ(set->state.fields.size(), static_cast<std::size_t>(cs.count)) << "fit_scene_cell " << fit;
      EXPECT_FALSE(set->state.fitted_to_scene);
    }
  }
}

TEST(CascadeFit, PastTheCoarsestCascadeAFarFieldCoversTheScene) {
  // The room is 12 m; cascades of 0.25 m cells reach 6 x 0.25 x 2^(count-1):
  // 12 m with four of them (no far field), 3 m with two (a far field last,
  // one grid over the scene's bounds; none when switched off).
  for (const int count : {4, 2})
    for (const bool far : {true, false}) {
      CascadeSettings cs;
      cs.count = count;
      cs.dims = glm::ivec3(6);
      cs.finest_cell = 0.25f;
      cs.fit_scene_cell = 0.0f;
      cs.far_field = far;
      Room room(cs);
      const runtime::ProbeCascades* set = first_frames_cascades(room);
      ASSERT_NE(set, nullptr);
      const auto& rt = room.app.world().resource<rt::RtScene>();
      const bool want = far && count == 2;
      ASSERT_EQ(needs_far_field(cs, rt.bounds_min(), rt.bounds_max()), count == 2);
      EXPECT_EQ(set->state.far_field, want) << count << " cascades, far field " << far;
      ASSERT_EQ(set->state.fields.size(), static_cast<std::size_t>(count + (want ? 1 : 0)));
      if (want) {
        EXPECT_EQ(set->state.fields.back()->settings().grid, ProbeGrid::centred_in(rt.bounds_min(), rt.bounds_max(), cs.dims));
      }
    }
}

TEST(GeometryCore, AGroundPlaneIsLeftOutAndARoomsOwnQuadsAreNot) {
  const auto box = [](glm::vec3 lo, glm::vec3 hi) { return SceneBox{lo, hi}; };
  // A 12 x 4 x 12 m building and a box in it on a 200 m ground plane: the plane goes.
  const SceneBox building = box({-6, 0, -6}, {6, 4, 6}), table = box({1, 0, -2}, {2, 1, -1});
  const SceneBox ground = box({-100, -0.001f, -100}, {100, -0.001f, 100});
  const std::vector<SceneBox> on_ground{building, table, ground};
  EXPECT_EQ(geometry_core(on_ground), building);
  // A room of six single quads (each flat, none larger than the others make): all stay.
  const std::vector<SceneBox> quads{box({-6, 0, -6}, {6, 0, 6}), box({-6, 4, -6}, {6, 4, 6}), box({-6, 0, -6}, {-6, 4, 6}),
                                    box({6, 0, -6}, {6, 4, 6}),  box({-6, 0, -6}, {6, 4, -6}), box({-6, 0, 6}, {6, 4, 6})};
  EXPECT_EQ(geometry_core(quads), box({-6, 0, -6}, {6, 4, 6}));
  // A plane only 3x the building (a courtyard) stays, and so does a hilly
  // 1 km terrain (50 m of relief is not flat).
  const std::vector<SceneBox> courtyard{building, box({-18, -0.001f, -18}, {18, -0.001f, 18})};
  EXPECT_EQ(geometry_core(courtyard), box({-18, -0.001f, -18}, {18, 4, 18}));
  const std::vector<SceneBox> terrain{building, box({-500, -20, -500}, {500, 30, 500})};
  EXPECT_EQ(geometry_core(terrain), box({-500, -20, -500}, {500, 30, 500}));
  // A lone plane is the scene; nothing at all is empty.
  const std::vector<SceneBox> lone{ground};
  EXPECT_EQ(geometry_core(lone), ground);
  EXPECT_TRUE(geometry_core(std::span<const SceneBox>{}).empty());
}

// A building on a ground plane far past the fitted grid's cells gets the grid
// over itself (as it would alone) and the far field over the plane, which
// lights only what the grid does not hold: the building's own walls, half a
// cell outside its outermost probes, stay the grid's (the far field's probes
// stand outside in the sky, and lit the rooms when they took those walls).
TEST(CascadeFit, ABuildingOnAGroundPlaneGetsOneGridOverItselfAndTheFarFieldBeyond) {
  for (const bool ddgi : {false, true}) {
    CascadeSettings cs;
    cs.dims = glm::ivec3(6);
    cs.fit_scene_cell = 2.5f;  // the room is 12 m: 2 m cells; the plane's 200 m is not
    Room room(cs, ddgi, 100.0f);
    room.app.jobs().run([&] { room.app.update(); });
    const auto& rt = room.app.world().resource<rt::RtScene>();
    const SceneBox building{{-6.0f, 0.0f, -6.0f}, {6.0f, 4.0f, 6.0f}};
    const auto check = [&](const auto& state, const auto& fields) {
      ASSERT_TRUE(state.fitted_to_scene) << "ddgi " << ddgi;
      ASSERT_TRUE(state.far_field) << "ddgi " << ddgi;
      ASSERT_EQ(fields.size(), 2u);
      const ProbeGrid fitted = ProbeGrid::centred_in(building.lo, building.hi, cs.dims);
      EXPECT_LT(glm::length(fields[0]->placement().min - fitted.min), 1e-4f);
      EXPECT_LT(glm::length(fields[0]->placement().max - fitted.max), 1e-4f);
      EXPECT_EQ(fields[1]->placement(), ProbeGrid::centred_in(rt.bounds_min(), rt.bounds_max(), cs.dims));
      EXPECT_EQ(fields[1]->settings().blend_cells, kFallbackBlendCells);
      // A point on a wall (outside the probes' box, inside the building),
      // one in a corner, and one on the ground outside.
      using F = std::remove_cvref_t<decltype(*fields[0])>;
      std::vector<const F*> view;
      for (const auto& f : fields) view.push_back(f.get());
      const std::span<const F* const> all(view);
      for (const glm::vec3 p : {glm::vec3(5.99f, 1.0f, 0.3f), glm::vec3(-5.99f, 3.99f, -5.99f), glm::vec3(0.0f, 0.01f, 5.99f)}) {
        const auto m = mix_at(all, p);
        EXPECT_EQ(m.field[0], view[0]) << p.x << " " << p.y << " " << p.z;
        EXPECT_EQ(m.count, 1);
      }
      EXPECT_EQ(mix_at(all, glm::vec3(30.0f, 0.0f, 10.0f)).field[0], view[1]);
    };
    if (ddgi) {
      room.app.world().view<const ddgi::DdgiCascades>().each([&](const ddgi::DdgiCascades& c) { check(c.state, c.state.fields); });
    } else {
      const runtime::ProbeCascades* set = nullptr;
      room.app.world().view<const runtime::ProbeCascades>().each([&](const runtime::ProbeCascades& c) { set = &c; });
      ASSERT_NE(set, nullptr);
      check(set->state, set->state.fields);
      // A probe ray's hit on the wall takes the fitted grid's bounce, not the far field's.
      const ProbeFeedbackSource src = set->state.fields[0]->feedback_source();
      EXPECT_LE(src.held_min().x, -6.0f + 1e-4f);
      EXPECT_GE(src.held_max().y, 4.0f - 1e-4f);
    }
  }
}

TEST(AuthoredVolumes, AMarkedNodeGetsAVolumeOverItsRotatedBoxAndAFlatOneIsRefusedByName) {
  ecs::World w;
  const ecs::Entity e = w.spawn();
  transform::Transform t = transform::Transform::from_translation({1.0f, 2.0f, 3.0f});
  t.rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0));  // swaps x and z extents
  w.emplace<transform::Transform>(e, t);
  w.emplace<scene::Name>(e, scene::Name{"Room"});
  w.emplace<scene::NodeMarkers>(e, scene::NodeMarkers{{std::string(runtime::kProbeVolumeMarker)}, {6.0f, 1.5f, 3.0f}});
  const ecs::Entity other = w.spawn();  // marked for something else
  w.emplace<transform::Transform>(other);
  w.emplace<scene::NodeMarkers>(other, scene::NodeMarkers{{"spawn_point"}, glm::vec3(1.0f)});
  ASSERT_EQ(runtime::attach_authored_volumes(w, 8), 1u);
  const auto& v = w.get<runtime::ProbeVolume>(e);
  EXPECT_NEAR(v.min.x, 1.0f - 3.0f, 1e-5f);
  EXPECT_NEAR(v.max.x, 1.0f + 3.0f, 1e-5f);
  EXPECT_NEAR(v.min.y, 2.0f - 1.5f, 1e-5f);
  EXPECT_NEAR(v.min.z, 3.0f - 6.0f, 1e-5f);
  EXPECT_NEAR(v.max.z, 3.0f + 6.0f, 1e-5f);
  // 8 cells on the longest axis (z, 12 m), proportionally fewer on the others.
  EXPECT_EQ(v.dims, glm::ivec3(4, 2, 8));
  EXPECT_EQ(w.try_get<runtime::ProbeVolume>(other), nullptr);

  ecs::World flat;
  const ecs::Entity f = flat.spawn();
  flat.emplace<transform::Transform>(f);
  flat.emplace<scene::Name>(f, scene::Name{"Floor volume"});
  flat.emplace<scene::NodeMarkers>(f, scene::NodeMarkers{{std::string(runtime::kProbeVolumeMarker)}, {4.0f, 0.0f, 4.0f}});
  try {
    runtime::attach_authored_volumes(flat);
    ADD_FAILURE() << "a flat volume was accepted";
  } catch (const std::exception& ex) {
    EXPECT_NE(std::string(ex.what()).find("Floor volume"), std::string::npos) << ex.what();
    EXPECT_NE(std::string(ex.what()).find("flat"), std::string::npos) << ex.what();
  }
}

TEST(DdgiCascades, TheSameScrollKeepsMapsSeedsTheEnteredAndNeverGivesABlackPixel) {
  CascadeSettings cs;
  cs.count = 2;
  cs.dims = glm::ivec3(6);
  cs.fit_scene_cell = 0.0f;
  cs.far_field = false;  // the two cascades alone: what scrolls
  Room room(cs, /*ddgi=*/true);
  auto& frame = room.app.world().resource<ddgi::DdgiFrame>();
  frame.width = 48;
  frame.height = 27;
  for (int f = 0; f < 32; ++f) room.app.jobs().run([&] { room.app.update(); });
  ddgi::DdgiCascades* set = nullptr;
  room.app.world().view<ddgi::DdgiCascades>().each([&](ddgi::DdgiCascades& c) { set = &c; });
  ASSERT_NE(set, nullptr);
  ASSERT_EQ(set->state.fields.size(), 2u);
  // Kept probes keep their maps; entered ones hold the coarser cascade's light.
  ddgi::DdgiVolume& fine = *set->state.fields[0];
  std::vector<std::vector<glm::vec3>> before;
  for (int q = 0; q < fine.grid().count(); ++q) before.push_back(fine.irradiance_map(q).texels);
  const glm::ivec3 cells{-1, 0, 1};
  EXPECT_EQ(fine.scroll(cells, set->state.fields[1].get()), 6 * 6 * 6 - 5 * 6 * 5);
  set->state.origins[0] += cells;  // as follow_camera would record it
  int seeded = 0;
  for (int q = 0; q < fine.grid().count(); ++q) {
    if (!fine.grid().entered_by_scroll(q, cells)) {
      ASSERT_EQ(fine.irradiance_map(q).texels, before[static_cast<std::size_t>(q)]) << "kept probe " << q;
    } else {
      float sum = 0;
      for (const glm::vec3& t : fine.irradiance_map(q).texels) sum += t.r + t.g + t.b;
      seeded += sum > 0;
    }
  }
  EXPECT_GT(seeded, 0) << "no entered probe got the coarser cascade's light";
  // Walk across cells: every pixel finite and lit.
  for (int f = 0; f < 24; ++f) {
    room.app.world().get_mut<transform::Transform>(room.camera) = Room::pose(0.15f * static_cast<float>(f + 1));
    room.app.jobs().run([&] { room.app.update(); });
    for (const glm::vec3& p : frame.gi.pixels) {
      ASSERT_TRUE(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b)) << "frame " << f;
      ASSERT_GT(p.r + p.g + p.b, 0.0f) << "black DDGI pixel at frame " << f;
    }
  }
}

TEST(CascadeMemory, ProbesThatHoldNoLightHoldNoMapsAndActiveOnesDo) {
  CascadeSettings cs;
  cs.count = 3;
  cs.dims = glm::ivec3(6);
  cs.fit_scene_cell = 0.0f;  // the coarse cascades reach outside the room: buried and far probes
  Room room(cs);
  for (int f = 0; f < 8; ++f) room.app.jobs().run([&] { room.app.update(); });
  const runtime::ProbeCascades* set = nullptr;
  room.app.world().view<const runtime::ProbeCascades>().each([&](const runtime::ProbeCascades& c) { set = &c; });
  ASSERT_NE(set, nullptr);
  int released = 0, held = 0;
  std::size_t bytes_if_all_held = 0, bytes = 0;
  for (const auto& f : set->state.fields) {
    for (int q = 0; q < f->grid().count(); ++q) {
      const bool lit = f->state(q) == ProbeState::Active || f->state(q) == ProbeState::Converged;
      EXPECT_EQ(f->states()[static_cast<std::size_t>(q)].held(), lit) << "probe " << q << " state " << static_cast<int>(f->state(q));
      released += lit ? 0 : 1;
      held += lit ? 1 : 0;
    }
    bytes += f->memory_bytes();
    bytes_if_all_held += ProbeField(f->settings()).memory_bytes();
  }
  EXPECT_GT(released, 0) << "no buried or far probe: the test sees nothing";
  EXPECT_GT(held, 0);
  EXPECT_LT(bytes, bytes_if_all_held) << "released maps must not count";
}

TEST(CascadeBlend, MoreFieldsThanTheStackHoldsStillReachTheOnesPastSixteen) {
  // 20 nested fields, each twice the size of the one before; a point only the
  // last four hold must come from field 16, not be clamped into field 15.
  std::vector<std::unique_ptr<ProbeField>> owned;
  std::vector<const ProbeField*> fields;
  for (int i = 0; i < 20; ++i) {
    ProbeFieldSettings s;
    s.map = MapLayout{4, 2};
    s.rays_per_probe = 4;
    const float half = std::ldexp(1.0f, i);
    s.grid = ProbeGrid{glm::vec3(-half), glm::vec3(half), glm::ivec3(2)};
    owned.push_back(std::make_unique<ProbeField>(s));
    fields.push_back(owned.back().get());
  }
  const glm::vec3 p(std::ldexp(1.0f, 16) - 1.0f, 0.0f, 0.0f);  // inside field 16 (half 65,536), outside 15
  const FieldMix m = fields_at(fields, p);
  EXPECT_EQ(m.field[0], fields[16]) << "got field " << (std::find(fields.begin(), fields.end(), m.field[0]) - fields.begin());
}

// The cascades' small maps are the real-time path's memory choice; the
// quality path keeps the run-time settings' maps, whose finer texels are
// closer to the oracle's mean (docs/results.md, issue 16).
TEST(CascadeMaps, SmallMapsOnTheRealTimePathThePresetsOnTheQualityPath) {
  probes::ProbeFieldSettings base;
  base.map = probes::MapLayout{100, 50};
  probes::CascadeSettings c;
  ASSERT_EQ(c.map_width, 32);
  const auto realtime = runtime::cascade_field_settings(base, c, 1, glm::ivec3(0), runtime::GiPath::Realtime);
  EXPECT_EQ(realtime.map.width, 32);
  EXPECT_EQ(realtime.map.height, 16);
  const auto quality = runtime::cascade_field_settings(base, c, 1, glm::ivec3(0), runtime::GiPath::Quality);
  EXPECT_EQ(quality.map.width, 100);
  EXPECT_EQ(quality.map.height, 50);
  c.map_width = 0;  // 0 = the preset's on both paths
  EXPECT_EQ(runtime::cascade_field_settings(base, c, 1, glm::ivec3(0), runtime::GiPath::Realtime).map.width, 100);
}
