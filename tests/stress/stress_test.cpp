// Numerical stress (issue 13, item 2): the real-time GI frame of one small
// room under scales, light strengths and bad values that no content author
// checked. Every case asks that no pixel and no probe holds a non-finite
// value; the known answers are physical: light transport is linear in the
// emitters' strength and does not change when the whole scene (lights
// included) is scaled, and with fixed input the image stops growing.
//
// The default cases run in the suite; the decade sweeps (DISABLED_ here) run
// with --gtest_also_run_disabled_tests, as the ctest `stress.sweep` when the
// build has TRANSGI_STRESS_SWEEPS=ON.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "../transgi/lambert.h"
#include "engine/app/app.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "runtime/probe_placement.h"
#include "runtime/transgi_plugin.h"

using namespace transgi;
using namespace engine;

namespace {

struct RoomCase {
  float scale = 1.0f;        // every length, the camera's near plane included
  float emission = 4.0f;     // the ceiling lamp's radiance
  float point_light = 0.0f;  // the point light's intensity at scale 1 (candela; scaled by scale^2)
  glm::ivec3 dims{4, 3, 4};  // probe grid
  bool keep_updating = false;  // on = converged probes keep tracing (no convergence skip)
  bool default_probes = false; // on = the default placement (cascades, fitted grid, far field) instead of a scaled volume
};

class Room {
 public:
  explicit Room(const RoomCase& c) : app_(app::AppOptions{.jobs = {.threads = 2}}) {
    auto& w = app_.world();
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    const float s = c.scale;
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_box(s * glm::vec3(2.0f, 1.5f, 2.0f), true, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_quad(s * glm::vec2(0.5f), 1)),
                std::make_shared<scene::MeshAsset>(scene::make_box(s * glm::vec3(0.4f), false, 2))};
    material::Material lamp = lambert(glm::vec3(0.0f));
    lamp.emissive_factor = glm::vec3(1.0f);
    lamp.emissive_strength = c.emission;
    lamp.double_sided = true;
    a.materials = {lambert(glm::vec3(0.7f)), lamp, lambert({0.8f, 0.4f, 0.2f})};
    w.insert_resource<scene::SceneAssets>(std::move(a));
    runtime::TransGISettings settings = runtime::realtime_preset();
    settings.probes.map = probes::MapLayout{16, 8};
    settings.probes.update_budget = 0;
    if (c.keep_updating) settings.probes.skip.skip_converged = false;
    app_.add_plugin<runtime::TransGIPlugin>(settings);
    spawn_mesh(0, transform::Transform{});
    transform::Transform lamp_at = transform::Transform::from_translation(s * glm::vec3(0.0f, 1.49f, 0.0f));
    lamp_at.rotation = glm::angleAxis(glm::pi<float>(), glm::vec3(1, 0, 0));  // facing down
    spawn_mesh(1, lamp_at);
    cube_ = spawn_mesh(2, transform::Transform::from_translation(s * glm::vec3(-0.6f, -1.1f, -0.5f)));
    if (c.point_light > 0) {
      light_ = w.spawn();
      w.emplace<transform::Transform>(light_, transform::Transform::from_translation(s * glm::vec3(0.8f, 0.5f, 0.3f)));
      w.emplace<scene::PunctualLight>(light_, scene::PunctualLight{.intensity = c.point_light * s * s});
    }
    const ecs::Entity camera = w.spawn();
    transform::Transform ct = transform::Transform::from_translation(s * glm::vec3(0.0f, 0.0f, 1.9f));
    w.emplace<transform::Transform>(camera, ct);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 1.2f, .znear = 0.01f * s});
    if (c.default_probes) {
      runtime::spawn_probes(w, runtime::ProbePlacement{});
      return;
    }
    const ecs::Entity volume = w.spawn();
    w.emplace<runtime::ProbeVolume>(volume, runtime::ProbeVolume{.min = s * glm::vec3(-1.8f, -1.3f, -1.8f),
                                                                 .max = s * glm::vec3(1.8f, 1.3f, 1.8f), .dims = c.dims});
  }

  // Runs `frames` frames and renders the last at 32x24.
  void run(int frames) {
    auto& frame = app_.world().resource<runtime::GiFrame>();
    for (int f = 0; f < frames; ++f) {
      frame.width = f + 1 == frames ? 32 : 0;
      frame.height = f + 1 == frames ? 24 : 0;
      app_.jobs().run([&] { app_.update(); });
    }
  }
  [[nodiscard]] const runtime::GiFrame& frame() { return app_.world().resource<runtime::GiFrame>(); }
  [[nodiscard]] ecs::World& world() { return app_.world(); }
  [[nodiscard]] ecs::Entity cube() const { return cube_; }
  [[nodiscard]] ecs::Entity light() const { return light_; }

  // Non-finite values in the images and in every probe's SH.
  [[nodiscard]] std::size_t non_finite() {
    std::size_t bad = 0;
    for (const image::ImageRGB* img : {&frame().gi, &frame().direct, &frame().full})
      for (const glm::vec3& p : img->pixels) bad += !(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b));
    app_.world().view<const runtime::ProbeVolume>().each([&](const runtime::ProbeVolume& v) {
      if (!v.field) return;
      for (float x : v.field->light_sh_all()) bad += !std::isfinite(x);
      for (float x : v.field->direct_sh_all()) bad += !std::isfinite(x);
    });
    return bad;
  }
  [[nodiscard]] double mean(const image::ImageRGB& img) const {
    double sum = 0;
    for (const glm::vec3& p : img.pixels) sum += (p.r + p.g + p.b) / 3.0;
    return img.pixels.empty() ? 0.0 : sum / static_cast<double>(img.pixels.size());
  }

 private:
  ecs::Entity spawn_mesh(std::uint32_t mesh, const transform::Transform& t) {
    auto& w = app_.world();
    const ecs::Entity e = w.spawn();
    w.emplace<transform::Transform>(e, t);
    w.emplace<scene::MeshInstance>(e, scene::MeshInstance{mesh});
    return e;
  }
  app::App app_;
  ecs::Entity cube_, light_;
};

constexpr int kFrames = 48;

struct Measured {
  double gi = 0, full = 0;
};

Measured measure(const RoomCase& c, int frames = kFrames) {
  Room room(c);
  room.run(frames);
  EXPECT_EQ(room.non_finite(), 0u) << "scale " << c.scale << ", emission " << c.emission << ", point light " << c.point_light;
  const Measured m{room.mean(room.frame().gi), room.mean(room.frame().full)};
  std::printf("[ measured ] scale %g, emission %g, point light %g: GI mean %.6g, full mean %.6g\n", c.scale, c.emission,
              c.point_light, m.gi, m.full);
  return m;
}

void expect_scale_invariant(float scale, bool default_probes = false) {
  const RoomCase base{.point_light = 3.0f, .default_probes = default_probes};
  const Measured one = measure(base);
  RoomCase scaled = base;
  scaled.scale = scale;
  const Measured got = measure(scaled);
  ASSERT_GT(one.gi, 0.0) << "the room must have GI to compare";
  // The grids, maps and offsets all scale; what remains is float rounding.
  EXPECT_NEAR(got.full / one.full, 1.0, 0.02) << "scale " << scale << ": full mean " << got.full << ", at 1 m " << one.full;
  EXPECT_NEAR(got.gi / one.gi, 1.0, 0.02) << "scale " << scale << ": GI mean " << got.gi << ", at 1 m " << one.gi;
}

void expect_linear_in_emission(float emission) {
  const Measured one = measure(RoomCase{.emission = 1.0f});
  const Measured got = measure(RoomCase{.emission = emission});
  ASSERT_GT(one.gi, 0.0);
  // Half-precision probe history keeps a per-probe power-of-two scale, so the
  // ratio holds to its rounding at any brightness.
  EXPECT_NEAR(got.gi / (emission * one.gi), 1.0, 0.01) << "emission " << emission << ": GI mean " << got.gi << ", expected "
                                                        << emission * one.gi;
  EXPECT_NEAR(got.full / (emission * one.full), 1.0, 0.01) << "emission " << emission;
}

}  // namespace

TEST(Stress, MillimetreAndTenKilometreRoomsLightAsAMetreRoom) {
  expect_scale_invariant(1e-3f);
  expect_scale_invariant(1e4f);
}

// Issue 37's far field: at the default placement a 40 km room is past every
// camera-centred cascade (32 m across), whose probes are far from every
// surface there and hold nothing; the far field over the scene's bounds
// lights it as a 4 m room (before it: 23 % of the full image lost). A 4 mm
// room gets one fitted grid.
TEST(Stress, AtTheDefaultPlacementMillimetreAndTenKilometreRoomsLightAsAMetreRoom) {
  expect_scale_invariant(1e-3f, true);
  expect_scale_invariant(1e4f, true);
}

TEST(Stress, LightIsLinearInEmitterStrengthFromOneMillionthToAMillion) {
  expect_linear_in_emission(1e-6f);
  expect_linear_in_emission(1e6f);
}

TEST(Stress, AnAllBlackSceneStaysExactlyBlack) {
  Room room(RoomCase{.emission = 0.0f});
  room.run(kFrames);
  EXPECT_EQ(room.non_finite(), 0u);
  EXPECT_EQ(room.mean(room.frame().full), 0.0) << "no light, yet the image holds some";
}

TEST(Stress, WithFixedInputTheImageStopsGrowing) {
  Room room(RoomCase{.point_light = 3.0f});
  room.run(96);
  const double early = room.mean(room.frame().gi);
  room.run(96);
  const double late = room.mean(room.frame().gi);
  EXPECT_EQ(room.non_finite(), 0u);
  EXPECT_LE(late, early * 1.02) << "GI mean grew from " << early << " to " << late << " with nothing changing";
  EXPECT_GE(late, early * 0.98) << "GI mean fell from " << early << " to " << late << " with nothing changing";
}

TEST(Stress, AGridOneProbeThickStaysFinite) {
  Room room(RoomCase{.point_light = 3.0f, .dims = {4, 1, 4}});
  room.run(kFrames);
  EXPECT_EQ(room.non_finite(), 0u);
  std::printf("[ measured ] one probe thick: GI mean %.6g, %d probes traced last frame\n", room.mean(room.frame().gi),
              room.frame().probe_stats.traced);
  EXPECT_GT(room.mean(room.frame().gi), 0.0);
}

TEST(Stress, NonFiniteTransformOrLightWrittenByCodeNeverReachesAPixel) {
  // What a script or editor bug could write straight into the components.
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (int what = 0; what < 4; ++what) {
    Room room(RoomCase{.point_light = 3.0f});
    room.run(8);
    auto& w = room.world();
    if (what == 0) w.get_mut<transform::Transform>(room.cube()).translation.x = nan;
    if (what == 1) w.get_mut<transform::Transform>(room.cube()).scale = inf;
    if (what == 2) w.get_mut<scene::PunctualLight>(room.light()).intensity = nan;
    if (what == 3) w.get_mut<transform::Transform>(room.light()).translation.y = inf;
    room.run(8);
    std::printf("[ measured ] non-finite case %d: full mean %.6g, GI mean %.6g\n", what, room.mean(room.frame().full),
                room.mean(room.frame().gi));
    EXPECT_EQ(room.non_finite(), 0u) << "case " << what;
    EXPECT_GT(room.mean(room.frame().full), 0.0) << "case " << what << ": the rest of the room must still be lit";
  }
}

TEST(StressSweep, DISABLED_EveryDecadeOfScale) {
  for (float s : {1e-3f, 1e-2f, 1e-1f, 1e1f, 1e2f, 1e3f, 1e4f}) expect_scale_invariant(s);
}

TEST(StressSweep, DISABLED_EveryDecadeOfEmitterStrength) {
  for (float k : {1e-6f, 1e-5f, 1e-4f, 1e-3f, 1e-2f, 1e-1f, 1e1f, 1e2f, 1e3f, 1e4f, 1e5f, 1e6f}) expect_linear_in_emission(k);
}

// 100,000 probe frames of a still scene: float accumulation must neither
// drift nor stall. Each probe's SH is a running estimate that moves with the
// noise of each frame's 100 rays (about 1.7 % relative RMS over all probes,
// up to 20 % on dim probes, measured), so the test asks what drift and stall
// would change: the field's total (the sum of every probe's DC coefficient,
// all channels) stays within 1 % of frame 1,000's, the frame-to-frame noise
// does not grow, and the estimates keep moving (a stalled history would
// freeze them).
TEST(StressSweep, DISABLED_ProbeShHoldsStillOverAHundredThousandFrames) {
  Room room(RoomCase{.point_light = 3.0f, .keep_updating = true});
  room.run(1000);
  const auto snapshot = [&] {
    std::vector<float> sh;
    room.world().view<const runtime::ProbeVolume>().each([&](const runtime::ProbeVolume& v) {
      sh.insert(sh.end(), v.field->light_sh_all().begin(), v.field->light_sh_all().end());
      sh.insert(sh.end(), v.field->direct_sh_all().begin(), v.field->direct_sh_all().end());
    });
    return sh;
  };
  const auto dc_sum = [](const std::vector<float>& sh) {
    double sum = 0;
    for (std::size_t p = 0; p + 75 <= sh.size(); p += 75) sum += sh[p] + sh[p + 25] + sh[p + 50];
    return sum;
  };
  const auto relative_change = [](const std::vector<float>& a, const std::vector<float>& b) {
    double diff = 0, norm = 0;
    for (std::size_t k = 0; k < a.size(); ++k) {
      diff += (a[k] - b[k]) * (a[k] - b[k]);
      norm += b[k] * b[k];
    }
    return std::sqrt(diff / norm);
  };
  const std::vector<float> at_1000 = snapshot();
  const double total_1000 = dc_sum(at_1000);
  std::vector<float> previous = at_1000;
  double worst_total = 0, first_noise = 0, last_noise = 0;
  const int blocks = std::getenv("TRANSGI_LONG_RUN_BLOCKS") ? std::atoi(std::getenv("TRANSGI_LONG_RUN_BLOCKS")) : 100;
  for (int block = 1; block < blocks; ++block) {
    room.run(1000);
    const std::vector<float> now = snapshot();
    ASSERT_EQ(now.size(), at_1000.size());
    const double total = dc_sum(now) / total_1000 - 1.0, noise = relative_change(now, previous);
    worst_total = std::max(worst_total, std::abs(total));
    if (block == 1) first_noise = noise;
    last_noise = noise;
    if (block % 10 == 1 || block + 1 == blocks)
      std::printf("[ measured ] frame %d: field total %+.3f %% from frame 1,000; all probes moved %.2f %% since frame %d\n",
                  (block + 1) * 1000, 100 * total, 100 * noise, block * 1000);
    previous = now;
  }
  EXPECT_EQ(room.non_finite(), 0u);
  EXPECT_LT(worst_total, 0.01) << "the field's total drifted " << 100 * worst_total << " % from frame 1,000";
  EXPECT_LT(last_noise, 2 * first_noise) << "the frame-to-frame change grew from " << 100 * first_noise << " % to " << 100 * last_noise;
  EXPECT_GT(last_noise, 1e-4) << "the probes stopped moving: the history stalled";
}
