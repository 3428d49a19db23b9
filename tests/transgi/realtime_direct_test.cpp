// The real-time direct light (issue 10, item 6; soft shadows, issue 37): the sun split out of the
// sky and shaded with one shadow ray per pixel, the residual sky through the
// probes. Its reference is the path tracer's direct pass with the map as it
// is (sun in the pixels); and it must not depend on any seed.
#include <gtest/gtest.h>

#include <set>

#include "lambert.h"
#include "sun_level.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/jobs/parallel_for.h"
#include "engine/math/sampling.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/procedural.h"
#include "runtime/transgi_plugin.h"
#include "shading/realtime_direct.h"

using namespace transgi;
using namespace engine;
using transgi_test::SunLevel;
using transgi_test::small_realtime;

TEST(RealtimeDirect, SunSplitFromTheSkyMatchesThePathTracedDirectPass) {
  SunLevel level(small_realtime(0, 1), 2);
  const int w = 64, h = 48;
  level.run(40, w, h);
  const auto& lights = level.app.world().resource<render::SceneLights>();
  ASSERT_GE(lights.set.split_sun_index(), 0) << "the realtime preset must split the sun out of the sky";
  EXPECT_GT(level.frame().direct_stats.shadow_rays, static_cast<std::size_t>(w * h / 4)) << "the sun must be shaded by shadow rays";
  const image::ImageRGB& got = level.frame().direct;
  const image::ImageRGB want = level.reference_direct(w, h, 512);
  // Where the two differ by design: the disk is a uniform cone (not its
  // pixels), the penumbra a fixed dither, and the sky a windowed degree-4
  // SH from probes. Over the image, and over sunlit and shadowed floor.
  double sum_got = 0, sum_want = 0, abs_diff = 0;
  for (std::size_t i = 0; i < got.pixels.size(); ++i) {
    const double g = glm::dot(got.pixels[i], glm::vec3(1.0f / 3)), r = glm::dot(want.pixels[i], glm::vec3(1.0f / 3));
    sum_got += g;
    sum_want += r;
    abs_diff += std::abs(g - r);
  }
  const double mean_rel = std::abs(sum_got - sum_want) / sum_want, l1_rel = abs_diff / sum_want;
  std::printf("[ measured ] direct mean %.4f vs reference %.4f (%.2f %%), relative L1 %.3f\n", sum_got / got.pixels.size(),
              sum_want / got.pixels.size(), 100 * mean_rel, l1_rel);
  EXPECT_LT(mean_rel, 0.03) << "expected the image's mean direct light within 3 % of " << sum_want / got.pixels.size()
                            << ", got " << sum_got / got.pixels.size();
  EXPECT_LT(l1_rel, 0.10) << "expected relative L1 < 0.10 (penumbra dither, probe sky), got " << l1_rel;
}

TEST(RealtimeDirect, FullImageIsIdenticalAcrossSeedsAndThreadCounts) {
  const int w = 48, h = 36, frames = 12;
  SunLevel a(small_realtime(0, 1), 2), b(small_realtime(12345, 77), 1);
  a.run(frames, w, h);
  b.run(frames, w, h);
  const image::ImageRGB &fa = a.frame().full, &fb = b.frame().full;
  ASSERT_EQ(fa.pixels.size(), fb.pixels.size());
  double mean = 0;
  for (std::size_t i = 0; i < fa.pixels.size(); ++i) {
    mean += fa.pixels[i].g;
    ASSERT_EQ(fa.pixels[i], fb.pixels[i]) << "pixel " << i << ": seed 0 on 2 threads gave " << fa.pixels[i].g
                                          << ", seed 12345 on 1 thread gave " << fb.pixels[i].g;
  }
  EXPECT_GT(mean, 0.0) << "the image must not be trivially black";
}

namespace {

// The sunlit level two frames in, at a size whose 4x4 tiles both image
// edges cut, and what shading one of its frames reads.
struct CutTiles {
  static constexpr int w = 37, h = 29;
  SunLevel level{small_realtime(0, 1), 2};
  CutTiles() { level.run(2, w, h); }
  ecs::World& world() { return level.app.world(); }
  const render::SceneLights& lights() { return world().resource<render::SceneLights>(); }
  const rt::RtScene& rt() { return world().resource<rt::RtScene>(); }
  const scene::SceneAssets& assets() { return world().resource<scene::SceneAssets>(); }
  render::CameraRays rays() {
    return render::CameraRays(world().get<scene::Camera>(level.camera), world().get<transform::WorldTransform>(level.camera), w, h);
  }
};

}  // namespace

TEST(RealtimeDirect, ShadedInsideTheGBufferLoopEqualsTheStandalonePass) {
  CutTiles scene;
  const int w = CutTiles::w, h = CutTiles::h;
  const auto& lights = scene.lights();
  const auto& rt = scene.rt();
  const auto& assets = scene.assets();
  const render::CameraRays rays = scene.rays();
  shading::GBuffer separate, fused;
  shading::RealtimeDirectStats separate_stats, fused_stats;
  image::ImageRGB want, got;
  scene.level.app.jobs().run([&] {
    shading::trace_gbuffer(rt, assets, rays, w, h, separate);
    want = shading::shade_direct_realtime(separate, rt, lights.set, rays, &separate_stats);
    shading::DirectTileShader shader(rt, lights.set, rays, w, h);
    shading::trace_gbuffer(rt, assets, rays, w, h, fused, &shader);
    got = shader.take(fused, &fused_stats);
  });
  EXPECT_GT(separate_stats.shadow_rays, 0u);
  EXPECT_EQ(fused_stats.shadow_rays, separate_stats.shadow_rays);
  ASSERT_EQ(got.pixels.size(), want.pixels.size());
  for (std::size_t i = 0; i < got.pixels.size(); ++i)
    ASSERT_EQ(got.pixels[i], want.pixels[i]) << "pixel " << i << ": inside the G-buffer loop " << got.pixels[i].r << ", standalone "
                                             << want.pixels[i].r;
}

TEST(RealtimeDirect, RecycledStorageFullOfGarbageGivesTheSameImage) {
  // The real-time frame hands last frame's image to the next shader, which
  // clears nothing: every tile must write each of its pixels (emission or
  // sky, then the lights added). Garbage (NaN, huge values) in the recycled
  // image must not reach the result. (The soft sun's visibility is fresh
  // storage each frame, so garbage cannot be planted there from here.)
  CutTiles scene;
  const int w = CutTiles::w, h = CutTiles::h;
  const auto& lights = scene.lights();
  ASSERT_GE(lights.set.split_sun_index(), 0) << "the scene must have a sun whose light is added to the tiles' pixels";
  const auto& rt = scene.rt();
  const auto& assets = scene.assets();
  const render::CameraRays rays = scene.rays();
  shading::GBuffer g;
  image::ImageRGB fresh, recycled;
  scene.level.app.jobs().run([&] {
    shading::DirectTileShader clean(rt, lights.set, rays, w, h);
    shading::trace_gbuffer(rt, assets, rays, w, h, g, &clean);
    fresh = clean.take(g);
    image::ImageRGB garbage(w, h);
    for (std::size_t i = 0; i < garbage.pixels.size(); ++i)
      garbage.pixels[i] = i % 2 ? glm::vec3(std::numeric_limits<float>::quiet_NaN()) : glm::vec3(1e30f, -7.0f, 3.0f);
    shading::DirectTileShader reused(rt, lights.set, rays, w, h, std::move(garbage));
    shading::trace_gbuffer(rt, assets, rays, w, h, g, &reused);
    recycled = reused.take(g);
  });
  ASSERT_EQ(recycled.pixels.size(), fresh.pixels.size());
  double sum = 0;
  for (std::size_t i = 0; i < fresh.pixels.size(); ++i) {
    sum += fresh.pixels[i].g;
    ASSERT_EQ(recycled.pixels[i], fresh.pixels[i]) << "pixel " << i << ": recycled storage " << recycled.pixels[i].r << ", fresh "
                                                   << fresh.pixels[i].r;
  }
  EXPECT_GT(sum, 0.0) << "the image must not be trivially black";
}

namespace {

// A floor under a plate at height 1 that covers x < 0, lit from straight
// above by a directional light with a disk of half-angle `radius`, seen
// from below the plate looking down. A floor point at x sees the part of
// the disk beyond the plate's edge: with s = -x / tan(radius) (height 1),
// the lit fraction is 1 - F(s), F(s) = (acos(-s) + s sqrt(1 - s^2)) / pi the
// share of a unit disk left of the chord at s.
struct PenumbraScene {
  app::App app{app::AppOptions{.jobs = {.threads = 2}}};
  ecs::Entity camera;
  PenumbraScene() {
    auto& w = app.world();
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({4, 4}, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_box({2.5f, 0.01f, 4.0f}, false, 0))};
    a.materials = {lambert(glm::vec3(0.5f))};
    w.insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    const ecs::Entity floor = w.spawn();
    w.emplace<transform::Transform>(floor);
    w.emplace<scene::MeshInstance>(floor, scene::MeshInstance{0});
    const ecs::Entity plate = w.spawn();
    w.emplace<transform::Transform>(plate, transform::Transform::from_translation({-2.5f, 1.0f, 0.0f}));
    w.emplace<scene::MeshInstance>(plate, scene::MeshInstance{1});
    camera = w.spawn();
    transform::Transform ct = transform::Transform::from_translation({0.0f, 0.9f, 0.0f});
    ct.rotation = glm::quatLookAtRH(glm::vec3(0, -1, 0), glm::vec3(0, 0, -1));
    w.emplace<transform::Transform>(camera, ct);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 1.0f});
    app.update();
  }
  // The direct pass at size x size, and each pixel's floor position.
  image::ImageRGB direct(float angular_radius, int size, shading::GBuffer& g) {
    auto& w = app.world();
    scene::PunctualLight sun;
    sun.type = scene::PunctualLight::Type::Directional;
    sun.color = glm::vec3(1.0f);
    sun.intensity = 1.0f;
    const render::LightSet lights(w.resource<rt::RtScene>(),
                                  {render::PunctualInstance{sun, glm::vec3(0.0f), glm::vec3(0, -1, 0), angular_radius}}, nullptr);
    const render::CameraRays rays(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), size, size);
    image::ImageRGB out;
    app.jobs().run([&] {
      shading::trace_gbuffer(w.resource<rt::RtScene>(), w.resource<scene::SceneAssets>(), rays, size, size, g);
      out = shading::shade_direct_realtime(g, w.resource<rt::RtScene>(), lights, rays);
    });
    return out;
  }
};

double disk_share_left_of(double s) {
  s = std::clamp(s, -1.0, 1.0);
  return (std::acos(-s) + s * std::sqrt(1.0 - s * s)) / 3.14159265358979;
}

}  // namespace

TEST(RealtimeDirect, ASunsPenumbraIsSmoothAndAsWideAsItsDisk) {
  // 0.1 rad: a 0.1 m half-width penumbra, 16 pixels either side of the edge.
  const float radius = 0.1f;
  PenumbraScene scene;
  shading::GBuffer g;
  const int size = 160;
  const image::ImageRGB img = scene.direct(radius, size, g);
  const float lit_value = 0.5f / 3.14159265f;  // albedo / pi x irradiance 1 (cos 1)
  double abs_sum = 0, worst = 0;
  int penumbra = 0, speckles = 0;
  for (int y = 1; y + 1 < size; ++y)
    for (int x = 1; x + 1 < size; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * size + x;
      ASSERT_TRUE(g.samples[p].hit);
      const double fx = g.position[p].x;
      const double want = 1.0 - disk_share_left_of(-fx / std::tan(radius));
      const double got = img.pixels[p].g / lit_value;
      if (want <= 0.02 || want >= 0.98) continue;
      ++penumbra;
      abs_sum += std::abs(got - want);
      worst = std::max(worst, std::abs(got - want));
      // A stipple: a pixel far from the median of its 3x3 neighbours.
      std::vector<float> around;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) around.push_back(img.pixels[p + static_cast<std::size_t>(dy * size + dx)].g / lit_value);
      std::nth_element(around.begin(), around.begin() + 4, around.end());
      speckles += std::abs(got - around[4]) > 0.1;
    }
  std::printf("[ measured ] penumbra: %d pixels, mean |lit fraction - analytic| %.4f, worst %.3f, %d speckles\n", penumbra,
              abs_sum / penumbra, worst, speckles);
  ASSERT_GT(penumbra, 20 * size) << "the penumbra should be about 32 pixels wide";
  EXPECT_LT(abs_sum / penumbra, 0.05) << "the penumbra's profile must follow the disk's";
  EXPECT_LT(worst, 0.2);
  EXPECT_LT(speckles, penumbra / 100) << "the penumbra must be smooth, not a dither";
}

TEST(RealtimeDirect, TheDiskPatternsShiftsVisitSixteenEvenOffsets) {
  std::set<std::pair<int, int>> seen;
  for (int k = 0; k < shading::kDiskPatternPhases; ++k) {
    const glm::ivec2 s = shading::disk_pattern_shift(k);
    EXPECT_TRUE(s.x % 2 == 0 && s.y % 2 == 0 && s.x >= 0 && s.x < 8 && s.y >= 0 && s.y < 8) << "phase " << k;
    seen.insert({s.x, s.y});
  }
  EXPECT_EQ(seen.size(), 16u);
  EXPECT_EQ(shading::disk_pattern_shift(0), glm::ivec2(0)) << "phase 0 is the unshifted pattern";
  EXPECT_EQ(shading::disk_pattern_shift(17), shading::disk_pattern_shift(1)) << "a cycle of 16";
}

// Where a penumbra is narrower than 8 pixels, or its filter window is not
// a multiple of 8 wide, the window does not hold each point of the 8x8
// pattern equally often, and the pattern's trace shows in one frame: the
// serrated edge of a cube's shadow where it stands on the floor (the sample
// level's cube and table). The temporal antialiasing's cycle mean of a
// still view averages the 16 shifted patterns. Against each floor pixel's
// visibility of the sun's disk by 1,024 stratified shadow rays, the cycle
// mean must be nearer than one frame.
TEST(RealtimeDirect, AContactShadowsCycleMeanFollowsTheDisk) {
  CutTiles scene;  // its sunlit level: a cube on a floor under a 3 degree sun
  const int w = 160, h = 120;
  const auto& lights = scene.lights();
  const auto& rt = scene.rt();
  const auto& assets = scene.assets();
  const render::CameraRays rays(scene.world().get<scene::Camera>(scene.level.camera),
                                scene.world().get<transform::WorldTransform>(scene.level.camera), w, h);
  const int sun = lights.set.split_sun_index();
  ASSERT_GE(sun, 0);
  const render::PunctualInstance& disk = lights.set.punctual_lights()[static_cast<std::size_t>(sun)];
  ASSERT_GT(disk.angular_radius, 0.0f);
  shading::GBuffer g;
  std::vector<image::ImageRGB> phases;
  const std::size_t n = static_cast<std::size_t>(w * h);
  std::vector<double> truth(n, -1.0);
  scene.level.app.jobs().run([&] {
    for (int k = 0; k < shading::kDiskPatternPhases; ++k) {
      shading::DirectTileShader shader(rt, lights.set, rays, w, h, {}, k);
      shading::trace_gbuffer(rt, assets, rays, w, h, g, &shader);
      phases.push_back(shader.take(g));
    }
    const math::Frame frame = math::Frame::from_normal(-disk.direction);
    engine::jobs::parallel_for<std::size_t>(0, n, 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t p = b; p < e; ++p) {
        // Floor pixels only (facing up, at height 0), in the light's reach.
        if (!g.samples[p].hit || g.samples[p].normal_world.y < 0.99f || std::abs(g.position[p].y) > 1e-3f) continue;
        const glm::vec3 o = rt::offset_ray_origin(g.position[p], glm::vec3(0, 1, 0), rt.offset_scale());
        int lit = 0;
        for (int i = 0; i < 32; ++i)
          for (int j = 0; j < 32; ++j) {
            const glm::vec2 u{(static_cast<float>(i) + 0.5f) / 32.0f, (static_cast<float>(j) + 0.5f) / 32.0f};
            const glm::vec3 d = frame.to_world(math::sample_uniform_cone(u, std::cos(disk.angular_radius)));
            lit += rt.occluded(rt::Ray{o, d, 0.0f, std::numeric_limits<float>::infinity()}) ? 0 : 1;
          }
        truth[p] = lit / 1024.0;
      }
    });
  });
  // The floor's unshadowed value: its brightest fully lit pixel's (a flat
  // Lambertian floor under a directional light is the same everywhere).
  double unshadowed = 0;
  for (std::size_t p = 0; p < n; ++p)
    if (truth[p] >= 1.0) unshadowed = std::max(unshadowed, static_cast<double>(phases[0].pixels[p].g));
  ASSERT_GT(unshadowed, 0.0);
  double one_error = 0, cycle_error = 0;
  int penumbra = 0;
  for (std::size_t p = 0; p < n; ++p) {
    if (truth[p] <= 0.02 || truth[p] >= 0.98) continue;
    double mean = 0;
    for (const image::ImageRGB& img : phases) mean += img.pixels[p].g / unshadowed;
    mean /= static_cast<double>(phases.size());
    ++penumbra;
    one_error += std::abs(phases[0].pixels[p].g / unshadowed - truth[p]);
    cycle_error += std::abs(mean - truth[p]);
  }
  ASSERT_GT(penumbra, 100);
  std::printf("[ measured ] contact shadow's penumbra: %d pixels; mean |lit fraction - 1,024 rays| one frame %.4f, cycle mean %.4f\n",
              penumbra, one_error / penumbra, cycle_error / penumbra);
  // Measured 0.80x (the rest is the filter's own width, the same in every
  // phase); one pattern for every phase would give 1.
  EXPECT_LT(cycle_error, 0.85 * one_error);
}

TEST(RealtimeDirect, ADeltaLightsShadowStaysHard) {
  PenumbraScene scene;
  shading::GBuffer g;
  const int size = 96;
  const image::ImageRGB img = scene.direct(0.0f, size, g);
  const float lit_value = 0.5f / 3.14159265f;
  for (std::size_t p = 0; p < img.pixels.size(); ++p) {
    const float got = img.pixels[p].g / lit_value;
    const float want = g.position[p].x > 0 ? 1.0f : 0.0f;
    if (std::abs(g.position[p].x) < 0.02f) continue;  // the pixels on the edge
    ASSERT_NEAR(got, want, 1e-4f) << "pixel " << p << " at x = " << g.position[p].x;
  }
}
