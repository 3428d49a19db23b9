// Temporal antialiasing (engine/render/temporal_aa.h) on synthetic frames:
// a camera looking down -Z at planes, each pixel's value computed exactly
// at its jittered sample, so what the resolve must give is known.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "engine/render/temporal_aa.h"

using namespace engine;

namespace {

constexpr int kW = 32, kH = 8;
const ecs::Entity kFront{1, 0}, kBack{2, 0};

// Object A: the half-plane x < edge (in A's own frame, moved by `a_offset`
// along x) at z = -1.5; object B: the plane z = -2 behind it. A pixel's
// value is shade(object, object-space x).
struct Synthetic {
  render::CameraRays camera{scene::Camera{.yfov_radians = 0.5f}, transform::Similarity{}, kW, kH};
  float edge = 0.0f, a_offset = 0.0f;
  std::function<float(ecs::Entity, float)> shade = [](ecs::Entity e, float) { return e == kFront ? 1.0f : 0.0f; };

  std::vector<glm::vec3> position = std::vector<glm::vec3>(kW * kH);
  std::vector<glm::vec4> guide = std::vector<glm::vec4>(kW * kH);
  std::vector<ecs::Entity> entity = std::vector<ecs::Entity>(kW * kH);
  image::ImageRGB image{kW, kH};   // this frame, resolved in place
  image::ImageRGB traced{kW, kH};  // this frame as traced, before the resolve

  void trace(glm::vec2 jitter) {
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * kW + x;
        const glm::vec3 d = camera.generate({x + 0.5f + jitter.x, y + 0.5f + jitter.y}).direction;
        glm::vec3 hit = d * (1.5f / -d.z);
        ecs::Entity e = kFront;
        if (!(hit.x - a_offset < edge)) {
          hit = d * (2.0f / -d.z);
          e = kBack;
        }
        position[p] = hit;
        guide[p] = glm::vec4(0, 0, 1, glm::length(hit));
        entity[p] = e;
        image.pixels[p] = glm::vec3(shade(e, e == kFront ? hit.x - a_offset : hit.x));
      }
  }
  std::vector<render::TaaObject> objects() const {
    transform::Similarity a;
    a.translation = glm::vec3(a_offset, 0, 0);
    return {{kFront, a}, {kBack, transform::Similarity{}}};
  }
  // One frame: traced at the TAA's jitter, resolved; returns the result.
  image::ImageRGB frame(render::TemporalAntialiasing& taa, const render::TemporalAaSettings& s, bool light_changed = false) {
    trace(taa.next_jitter(s));
    traced = image;
    image::ImageRGB* layers[] = {&image};
    const auto objs = objects();
    taa.resolve(camera, render::TaaSurfaces{position, guide, entity}, objs, layers, s, light_changed);
    return image;
  }
  // Film x of A's edge on screen (A's plane at z = -1.5).
  float edge_film_x() const {
    const glm::vec3 p(edge + a_offset, 0.0f, -1.5f);
    return camera.project(p)->x;
  }
};

// A blend of 0.1, so the expectations below read simply.
render::TemporalAaSettings on() { return render::TemporalAaSettings{.enabled = true, .blend = 0.1f}; }

// The share of the jitter cycle's samples in pixel x that land left of film x `edge`.
float covered(int x, float edge, int phases) {
  int n = 0;
  for (int i = 0; i < phases; ++i) n += static_cast<float>(x) + 0.5f + render::taa_jitter(static_cast<std::uint64_t>(i), phases).x < edge;
  return static_cast<float>(n) / static_cast<float>(phases);
}

}  // namespace

TEST(TemporalAa, JitterCycleIsCentredAndWithinThePixel) {
  glm::vec2 mean(0.0f);
  for (int i = 0; i < 16; ++i) {
    const glm::vec2 j = render::taa_jitter(static_cast<std::uint64_t>(i), 16);
    EXPECT_GE(j.x, -0.5f);
    EXPECT_LT(j.x, 0.5f);
    EXPECT_GE(j.y, -0.5f);
    EXPECT_LT(j.y, 0.5f);
    mean += j;
  }
  EXPECT_NEAR(mean.x / 16, 0.0f, 0.04f);
  EXPECT_NEAR(mean.y / 16, 0.0f, 0.04f);
  render::TemporalAntialiasing taa;
  EXPECT_EQ(taa.next_jitter(render::TemporalAaSettings{}), glm::vec2(0.0f)) << "no jitter when disabled";
}

TEST(TemporalAa, AStillSilhouetteConvergesToItsCoverage) {
  // A's edge between pixels: the pixel it crosses must settle at the share
  // of the jitter samples that see A, not flip between A and B.
  Synthetic v;
  v.edge = 0.03f;
  render::TemporalAntialiasing taa;
  const float film_edge = v.edge_film_x();
  const int x_edge = static_cast<int>(std::floor(film_edge));
  std::vector<float> last;
  for (int f = 0; f < 96; ++f) {
    const image::ImageRGB out = v.frame(taa, on());
    if (f >= 80) last.push_back(out.at(x_edge, kH / 2).r);
  }
  const float want = covered(x_edge, film_edge, 16);
  ASSERT_GT(want, 0.15f);
  ASSERT_LT(want, 0.85f);
  float lo = 1, hi = 0, mean = 0;
  for (float l : last) {
    lo = std::min(lo, l);
    hi = std::max(hi, l);
    mean += l / static_cast<float>(last.size());
  }
  std::printf("[ measured ] edge pixel %d: coverage %.3f, resolved %.3f (%.3f..%.3f over the last 16 frames)\n", x_edge, want, mean,
              lo, hi);
  EXPECT_NEAR(mean, want, 0.1f) << "the edge pixel should hold A's share of it";
  EXPECT_LT(hi - lo, 0.2f) << "and hold it still, not flicker with the jitter";
  const image::ImageRGB out = v.frame(taa, on());
  EXPECT_FLOAT_EQ(out.at(x_edge - 3, kH / 2).r, 1.0f);
  EXPECT_FLOAT_EQ(out.at(x_edge + 3, kH / 2).r, 0.0f);
}

TEST(TemporalAa, AStillEdgeShowsItsExactCoverageEveryFrameOnceACycleIsAveraged) {
  // With the cycle mean (the default) the edge pixel shows exactly the mean
  // of the 16 jitter samples, the same in every frame; the exponential
  // history alone keeps a ripple of the jitter (measured here too, so the
  // test shows what it guards).
  Synthetic v;
  v.edge = 0.03f;
  const int x_edge = static_cast<int>(std::floor(v.edge_film_x()));
  const float want = covered(x_edge, v.edge_film_x(), 16);
  const auto spread = [&](bool cycle_mean, float* last_value) {
    render::TemporalAntialiasing taa;
    render::TemporalAaSettings s{.enabled = true, .cycle_mean = cycle_mean};  // the default blend, 1/16
    float lo = 1, hi = 0;
    for (int f = 0; f < 96; ++f) {
      const float value = v.frame(taa, s).at(x_edge, kH / 2).r;
      if (f >= 64) {
        lo = std::min(lo, value);
        hi = std::max(hi, value);
      }
      *last_value = value;
    }
    return hi - lo;
  };
  float with = 0, without = 0;
  const float ripple_with = spread(true, &with), ripple_without = spread(false, &without);
  std::printf("[ measured ] edge pixel %d, coverage %.4f: frames 64-95 range %.2g with the cycle mean (shows %.4f), "
              "%.2g without\n", x_edge, want, ripple_with, with, ripple_without);
  EXPECT_LT(ripple_with, 1e-6f) << "the same value every frame";
  EXPECT_NEAR(with, want, 1e-5f) << "the exact mean over the jitter cycle";
  EXPECT_GT(ripple_without, 0.01f) << "the exponential history ripples (else this test shows nothing)";
  // Changed light drops the cycle: the next frame follows the exponential path.
  render::TemporalAntialiasing taa;
  render::TemporalAaSettings s{.enabled = true};
  for (int f = 0; f < 64; ++f) v.frame(taa, s);
  v.shade = [](ecs::Entity e, float) { return e == kFront ? 0.5f : 0.0f; };
  const float after = v.frame(taa, s, true).at(x_edge - 3, kH / 2).r;
  EXPECT_LT(after, 0.99f) << "a light change shows at once, not after the cycle";
}

TEST(TemporalAa, WhereAnObjectMovedAwayThePixelsRestartWithNoGhost) {
  Synthetic v;
  v.shade = [](ecs::Entity e, float) { return e == kFront ? 5.0f : 1.0f; };
  render::TemporalAntialiasing taa;
  for (int f = 0; f < 32; ++f) v.frame(taa, on());
  const int old_edge = static_cast<int>(v.edge_film_x());
  v.a_offset = -0.8f;  // A jumps left: the pixels between the two edges now see B
  const int new_edge = static_cast<int>(v.edge_film_x());
  ASSERT_GT(old_edge - new_edge, 6);
  const image::ImageRGB out = v.frame(taa, on(), true);
  for (int x = new_edge + 2; x < old_edge - 1; ++x)
    for (int y = 0; y < kH; ++y) EXPECT_FLOAT_EQ(out.at(x, y).r, 1.0f) << "pixel " << x << ", " << y << " kept A's old light";
  EXPECT_GT(taa.stats().rejected, 0u);
}

TEST(TemporalAa, AMovingObjectsHistoryFollowsIt) {
  // A carries a gradient in its own frame and slides right a little each
  // frame: its pixels' history must come from where the same point was.
  Synthetic v;
  v.edge = 0.3f;
  v.shade = [](ecs::Entity e, float x_obj) { return e == kFront ? 2.0f + 4.0f * x_obj : 0.0f; };
  render::TemporalAntialiasing taa;
  float worst = 0;
  for (int f = 0; f < 40; ++f) {
    v.a_offset = 0.01f * static_cast<float>(f);
    const image::ImageRGB out = v.frame(taa, on(), true);
    if (f < 8) continue;
    Synthetic centre = v;  // this frame at the pixels' centres: what the average over the jitter tends to
    centre.trace(glm::vec2(0.0f));
    const int edge = static_cast<int>(v.edge_film_x());
    for (int x = 2; x < edge - 2; ++x) worst = std::max(worst, std::abs(out.at(x, kH / 2).r - centre.image.at(x, kH / 2).r));
  }
  // Without following the motion the history would lag by 0.01 x 4 per
  // frame over ~10 frames of blend: about 0.3.
  std::printf("[ measured ] worst |resolved - this frame at pixel centres| inside the moving object: %.4f\n", worst);
  EXPECT_LT(worst, 0.08f);
}

TEST(TemporalAa, ChangedLightIsClampedOnlyWhenSaid) {
  Synthetic v;
  v.shade = [](ecs::Entity, float) { return 1.0f; };
  render::TemporalAntialiasing still, told;
  for (int f = 0; f < 16; ++f) {
    v.frame(still, on());
    v.frame(told, on());
  }
  v.shade = [](ecs::Entity, float) { return 0.0f; };  // the light goes out
  const float kept = v.frame(still, on(), false).at(kW / 2, kH / 2).r;
  const float clamped = v.frame(told, on(), true).at(kW / 2, kH / 2).r;
  EXPECT_NEAR(kept, 0.9f, 1e-5f) << "unclamped, the history fades at the blend rate";
  EXPECT_FLOAT_EQ(clamped, 0.0f) << "clamped to this frame's neighbours: out at once";
}

TEST(TemporalAa, ASmallChangeOfLightBlendsAndALargeOneIsClamped) {
  // Under a slowly moving sun each frame's light differs a little from the
  // last (and a probe's update jumps by a few per cent): within the clamp's
  // margin that is blended over frames, not passed through as flicker.
  Synthetic v;
  render::TemporalAntialiasing taa;
  v.shade = [](ecs::Entity, float) { return 1.0f; };
  for (int f = 0; f < 16; ++f) v.frame(taa, on());
  v.shade = [](ecs::Entity, float) { return 0.95f; };
  const float small = v.frame(taa, on(), true).at(kW / 2, kH / 2).r;
  const float margin = on().clamp_margin;
  ASSERT_GT(margin, 0.05f);
  EXPECT_NEAR(small, 1.0f - 0.1f * 0.05f, 1e-5f) << "a 5 % change is within the margin: blended at the blend rate";
  v.shade = [](ecs::Entity, float) { return 0.5f; };
  const float large = v.frame(taa, on(), true).at(kW / 2, kH / 2).r;
  // Clamped to 0.5 x (1 + margin), then blended with 0.5.
  const float clamped = 0.5f * (1.0f + margin);
  EXPECT_NEAR(large, clamped + 0.1f * (0.5f - clamped), 1e-5f) << "a halving is clamped to the margin around this frame";
}

TEST(TemporalAa, VectorisedRowsEqualThePerPixelPath) {
  // A textured background, an object moving beside it now and then, the
  // light changing every other frame: every branch of the still camera's
  // rows, against the per-pixel path.
  Synthetic fast, slow;
  const auto shade = [](ecs::Entity e, float x) { return e == kFront ? 3.0f + std::sin(9.0f * x) : 0.5f + 0.4f * std::cos(13.0f * x); };
  fast.shade = slow.shade = shade;
  render::TemporalAaSettings per_pixel = on();
  per_pixel.vectorised_rows = false;
  render::TemporalAntialiasing a, b;
  float worst = 0.0f;
  for (int f = 0; f < 40; ++f) {
    fast.a_offset = slow.a_offset = f % 7 < 3 ? 0.02f * static_cast<float>(f % 7) : 0.0f;
    const bool light_changed = f % 2 == 0;
    const image::ImageRGB x = fast.frame(a, on(), light_changed);
    const image::ImageRGB y = slow.frame(b, per_pixel, light_changed);
    for (std::size_t i = 0; i < x.size(); ++i)
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(x.pixels[i][c] - y.pixels[i][c]));
    EXPECT_EQ(a.stats().reused, b.stats().reused) << "frame " << f;
    EXPECT_EQ(a.stats().rejected, b.stats().rejected) << "frame " << f;
  }
  EXPECT_LT(worst, 1e-5f) << "the same blend, only another order of float operations";
}
