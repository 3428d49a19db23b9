// The upsampling plan (shading/upsampling.h): its known answers on flat and
// stepped guides, and its vector kernel against the scalar reference.
#include <gtest/gtest.h>

#include <cstring>

#include "engine/core/cpu_isa.h"
#include "engine/math/sampling.h"
#include "shading/realtime_gi.h"
#include "shading/upsampling.h"

using namespace transgi::shading;

namespace {

std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

// A flat wall facing the camera at depth 2, with a nearer box (depth 1) over
// columns [box0, box1).
std::vector<glm::vec4> wall_with_box(int w, int h, int box0, int box1) {
  std::vector<glm::vec4> g(static_cast<std::size_t>(w) * h, glm::vec4(0, 0, 1, 2));
  for (int y = 0; y < h; ++y)
    for (int x = box0; x < box1; ++x) g[static_cast<std::size_t>(y) * w + x].w = 1;
  return g;
}

}  // namespace

TEST(Upsampling, FlatSurfaceWeighsItsCellsBilinearly) {
  // Half resolution: pixel x sits at cell coordinate (x + 0.5) / 2 - 0.5, so
  // pixel 5 takes 0.75 of cell 2 and 0.25 of cell 3.
  const int w = 40, h = 20;
  const std::vector<glm::vec4> guide(static_cast<std::size_t>(w) * h, glm::vec4(0, 0, 1, 2));
  RealtimeGiSettings s;
  for (UpsamplingIsa isa : {UpsamplingIsa::Scalar, best_upsampling_isa()}) {
    UpsamplingPlan u;
    plan_upsampling(guide, w, h, s, u, isa);
    ASSERT_EQ(u.grid_w, 20);
    ASSERT_EQ(u.grid_h, 10);
    const int x = 5, y = 7;  // odd, odd: cells (2, 3) and (3, 4), weights 0.75 and 0.25 per axis
    const std::size_t p = static_cast<std::size_t>(y) * w + x;
    ASSERT_EQ(u.kind[p], UpsamplingPlan::kUpsampled);
    EXPECT_EQ(u.cell(0, x, y), 3u * 20 + 2);
    EXPECT_EQ(u.cell(3, x, y), 4u * 20 + 3);
    const float expected[4] = {0.75f * 0.75f, 0.25f * 0.75f, 0.75f * 0.25f, 0.25f * 0.25f};
    for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(u.weight[k][p], expected[k], 1e-6f) << "tap " << k;
  }
}

TEST(Upsampling, APixelNoCellResemblesIsDecodedOnItsOwn) {
  const int w = 64, h = 8;
  // A box one pixel wide on an even column: cells decode odd columns, so no
  // cell lands on it, and it must be decoded on its own.
  const std::vector<glm::vec4> guide = wall_with_box(w, h, 20, 21);
  UpsamplingPlan u;
  plan_upsampling(guide, w, h, RealtimeGiSettings{}, u);
  for (int y = 0; y < h; ++y) {
    EXPECT_EQ(u.kind[static_cast<std::size_t>(y) * w + 20], UpsamplingPlan::kOwn) << "row " << y;
    // The wall pixels either side keep their weights summing to 1.
    for (int x : {19, 21}) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      ASSERT_EQ(u.kind[p], UpsamplingPlan::kUpsampled) << "pixel " << x << ", row " << y;
      float sum = 0;
      for (std::size_t k = 0; k < 4; ++k) sum += u.weight[k][p];
      EXPECT_NEAR(sum, 1.0f, 1e-6f);
    }
  }
}

TEST(Upsampling, VectorKernelEqualsTheReferenceBitForBit) {
  // Every vector kernel this machine may run (TRANSGI_MAX_ISA caps them).
  std::vector<UpsamplingIsa> kernels;
  if (engine::cpu::isa_enabled(engine::cpu::Isa::Avx512)) kernels.push_back(UpsamplingIsa::Avx512);
  if (engine::cpu::isa_enabled(engine::cpu::Isa::Avx2)) kernels.push_back(UpsamplingIsa::Avx2);
  if (kernels.empty()) GTEST_SKIP() << "no AVX2 or AVX-512 on " << engine::cpu::isa_summary() << ": only the reference runs";
  for (const UpsamplingIsa isa : kernels) {
    SCOPED_TRACE(upsampling_isa_name(isa));
    engine::math::Pcg32 rng(21, 5);
    // Sizes that are and are not multiples of 16, scales that are not halves,
    // normal powers from 0, and guides with misses, depth steps and NaN.
    const int sizes[][2] = {{64, 36}, {77, 41}, {16, 3}, {15, 9}};
    const float scales[] = {0.5f, 0.37f, 1.0f, 0.25f};
    const int powers[] = {8, 0, 1, 5};
    int compared = 0, own = 0;
    for (int c = 0; c < 4; ++c) {
      const int w = sizes[c][0], h = sizes[c][1];
      std::vector<glm::vec4> guide(static_cast<std::size_t>(w) * h);
      for (glm::vec4& g : guide) {
        const glm::vec3 n = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
        const float r = rng.next_float();
        const float depth = r < 0.1f ? 0.0f : r < 0.5f ? 1.0f + 0.01f * rng.next_float() : 3.0f + rng.next_float();
        g = glm::vec4(n, depth);
      }
      guide[3].x = NAN;
      RealtimeGiSettings s;
      s.resolution_scale = scales[c];
      s.normal_power = powers[c];
      UpsamplingPlan ref, fast;
      plan_upsampling(guide, w, h, s, ref, UpsamplingIsa::Scalar);
      plan_upsampling(guide, w, h, s, fast, isa);
      for (std::size_t p = 0; p < guide.size(); ++p) {
        ASSERT_EQ(static_cast<int>(fast.kind[p]), static_cast<int>(ref.kind[p])) << "case " << c << ", pixel " << p;
        own += ref.kind[p] == UpsamplingPlan::kOwn;
        if (ref.kind[p] != UpsamplingPlan::kUpsampled) continue;
        for (std::size_t k = 0; k < 4; ++k)
          ASSERT_EQ(bits(fast.weight[k][p]), bits(ref.weight[k][p]))
              << "case " << c << ", pixel " << p << ", tap " << k << ": " << fast.weight[k][p] << " against " << ref.weight[k][p];
        ++compared;
      }
    }
    EXPECT_GT(compared, 1000) << "too few upsampled pixels to compare";
    EXPECT_GT(own, 100) << "the lone-pixel path went untested";
  }
}
