// The real-time frame's histories together (issue 37): the antialiasing
// (engine/render/temporal_aa.h) and the GI's checkerboard reuse
// (shading/gi_history.h) must not show an object where it was. Two copies
// of one level run the same frames; the cube moves 0.3 m; one renders the
// next frame with its histories, the other as a camera cut (GiFrame::
// camera_cut: both forgotten, the same jitter). Against the
// path tracer's image of the new state, the pixels the cube left must be
// no worse with the histories than without.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/render/camera_rays.h"
#include "engine/rt/rt_scene.h"
#include "engine/transform/transform.h"
#include "sun_level.h"

using namespace transgi;
using namespace engine;
using transgi_test::SunLevel;
using transgi_test::small_realtime;

namespace {

constexpr int kW = 64, kH = 48;

void run_imaged(SunLevel& level, int frames) {
  for (int f = 0; f < frames; ++f) {
    level.frame().width = kW;
    level.frame().height = kH;
    level.app.jobs().run([&] { level.app.update(); });
  }
}

// What the camera ray through each pixel's centre hits.
std::vector<ecs::Entity> entities_seen(SunLevel& level) {
  auto& w = level.app.world();
  const render::CameraRays rays(w.get<scene::Camera>(level.camera), w.get<transform::WorldTransform>(level.camera), kW, kH);
  std::vector<ecs::Entity> out(static_cast<std::size_t>(kW) * kH);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      rt::Hit hit;
      if (w.resource<rt::RtScene>().intersect(rays.generate({x + 0.5f, y + 0.5f}), hit))
        out[static_cast<std::size_t>(y) * kW + x] = hit.entity;
    }
  return out;
}

double rmse_in(const image::ImageRGB& a, const image::ImageRGB& b, const std::vector<std::uint8_t>& mask) {
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    const glm::vec3 d = glm::min(a.pixels[i], glm::vec3(1.0f)) - glm::min(b.pixels[i], glm::vec3(1.0f));
    sum += glm::dot(d, d) / 3.0;
    ++n;
  }
  return std::sqrt(sum / n);
}

}  // namespace

TEST(FrameHistory, TheFrameAfterAMoveShowsNoGhostWhereTheObjectWas) {
  runtime::TransGISettings settings = small_realtime(0, 1);
  ASSERT_TRUE(settings.taa.enabled && settings.realtime.reuse_history) << "the real-time preset keeps both histories";
  SunLevel with(settings, 2), cleared(settings, 2);
  run_imaged(with, 24);
  run_imaged(cleared, 24);
  const std::vector<ecs::Entity> before = entities_seen(with);
  for (SunLevel* level : {&with, &cleared})
    level->app.world().get_mut<transform::Transform>(level->cube).translation.x += 0.3f;
  cleared.frame().camera_cut = true;  // the same frame, its histories forgotten
  run_imaged(with, 1);
  run_imaged(cleared, 1);
  const std::vector<ecs::Entity> after = entities_seen(with);
  std::vector<std::uint8_t> left(before.size(), 0);
  int n = 0;
  for (std::size_t i = 0; i < before.size(); ++i)
    if (before[i] == with.cube && after[i] != with.cube) n += left[i] = 1;
  ASSERT_GT(n, 30) << "the cube should uncover a patch of the floor";
  const image::ImageRGB reference = with.reference(kW, kH, 256, render::Pass::Full);
  const double err_with = rmse_in(with.frame().full, reference, left), err_cleared = rmse_in(cleared.frame().full, reference, left);
  std::printf("[ measured ] %d uncovered pixels: RMSE with the histories %.4f, with them cleared %.4f (ratio %.3f)\n", n,
              err_with, err_cleared, err_with / err_cleared);
  // The issue asks for 1.2x; an antialiased edge that kept some of the cube
  // (1.19x, before TemporalAntialiasing::moved_beside) must fail too.
  EXPECT_LE(err_with, 1.1 * err_cleared + 1e-3) << "the histories kept some of the cube where it was";
  EXPECT_FALSE(cleared.frame().camera_cut) << "a cut is for one frame";
}

TEST(FrameHistory, AntialiasedPassesAreTheMeanOfTheFramesTheyHold) {
  // A still camera over a still scene: no history is clamped, and a history
  // of n <= 1 / blend frames is their plain mean. So with the passes
  // antialiased, frame 8's gi and direct passes are the means of the eight
  // raw passes a copy without them rendered, and the full image is the
  // same in both.
  runtime::TransGISettings settings = small_realtime(0, 1);
  ASSERT_LE(8.0f * settings.taa.blend, 1.0f);
  SunLevel raw(settings, 2), resolved(settings, 2);
  resolved.frame().antialias_passes = true;
  constexpr int kFrames = 8;
  image::ImageRGB gi_mean(kW, kH), direct_mean(kW, kH);
  for (int f = 0; f < kFrames; ++f) {
    run_imaged(raw, 1);
    for (std::size_t i = 0; i < gi_mean.size(); ++i) {
      gi_mean.pixels[i] += raw.frame().gi.pixels[i] / static_cast<float>(kFrames);
      direct_mean.pixels[i] += raw.frame().direct.pixels[i] / static_cast<float>(kFrames);
    }
  }
  run_imaged(resolved, kFrames);
  float worst_gi = 0, worst_direct = 0, worst_full = 0, jitter_spread = 0;
  for (std::size_t i = 0; i < gi_mean.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const auto rel = [](float a, float b) { return std::abs(a - b) / (1e-3f + std::abs(b)); };
      worst_gi = std::max(worst_gi, rel(resolved.frame().gi.pixels[i][c], gi_mean.pixels[i][c]));
      worst_direct = std::max(worst_direct, rel(resolved.frame().direct.pixels[i][c], direct_mean.pixels[i][c]));
      worst_full = std::max(worst_full, std::abs(resolved.frame().full.pixels[i][c] - raw.frame().full.pixels[i][c]));
      jitter_spread = std::max(jitter_spread, rel(raw.frame().gi.pixels[i][c], gi_mean.pixels[i][c]));
    }
  std::printf("[ measured ] worst relative difference from the mean: gi %.2e, direct %.2e; the last raw frame's gi %.2e\n",
              worst_gi, worst_direct, jitter_spread);
  EXPECT_GT(jitter_spread, 0.05f) << "the jitter changes some pixels' passes, or this test shows nothing";
  EXPECT_LT(worst_gi, 1e-4f);
  EXPECT_LT(worst_direct, 1e-4f);
  EXPECT_EQ(worst_full, 0.0f) << "the full image does not depend on whether the passes are resolved";
}
