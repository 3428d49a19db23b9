// shaders/probe_interpolation.comp against probes::interpolate_probes_reference
// (its CPU stage) on a scrolled grid with relocated probes, random depth
// moments and unusable probes; and a known answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/math/rng.h"
#include "gpu/vulkan_probe_interpolator.h"
#include "gpu_fixture.h"

using namespace transgi;

namespace {

struct Scene {
  probes::ProbeGrid grid;
  probes::MapLayout layout{20, 10};  // small maps keep the upload small; the kernel reads any size
  std::vector<probes::ProbeMapState> states;
  std::vector<std::uint8_t> usable;
  std::vector<float> sh;
};

Scene random_scene(std::uint64_t seed) {
  Scene s;
  s.grid = probes::ProbeGrid{glm::vec3(-1.0f, 0.0f, -2.0f), glm::vec3(3.0f, 2.0f, 1.5f), glm::ivec3(4, 3, 5)};
  s.grid.scroll = glm::ivec3(1, 2, 0);
  engine::math::Pcg32 rng(seed, 5);
  const int count = s.grid.count();
  const float unit = s.grid.min_spacing();
  s.grid.offsets.resize(static_cast<std::size_t>(count));
  for (auto& o : s.grid.offsets) o = 0.3f * unit * glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
  s.states.resize(static_cast<std::size_t>(count));
  s.usable.resize(static_cast<std::size_t>(count));
  s.sh.resize(static_cast<std::size_t>(count) * 75);
  for (int q = 0; q < count; ++q) {
    auto& st = s.states[static_cast<std::size_t>(q)];
    st.depth.reset(s.layout.texel_count(), unit);
    // Hit distances of 0.2 to 1.5 cells: a third of the corners or so end up
    // occluded; a few texels never hit (NaN mean: visible).
    for (int t = 0; t < s.layout.texel_count(); ++t) {
      const float mean = rng.next_float() < 0.05f ? NAN : unit * (0.2f + 1.3f * rng.next_float());
      st.depth.set(static_cast<std::size_t>(t), mean, 0.01f * unit * unit * rng.next_float());
    }
    s.usable[static_cast<std::size_t>(q)] = rng.next_float() < 0.1f ? 0 : 1;
    for (int k = 0; k < 75; ++k) s.sh[static_cast<std::size_t>(q) * 75 + k] = rng.next_float() - 0.3f;
  }
  return s;
}

}  // namespace

// 3,000 points in and around the box. The kernel is the CPU's arithmetic
// in the same order, but the GPU may contract a*b+c into an FMA and the CPU
// (built with -ffp-contract=off) does not: a point within an ulp of a texel
// border or of the visibility threshold can fall the other way. So: at most
// 0.5 % of the points may prune differently (measured 0); every other point
// has the same probes, fallback flag, and weights and blended SH to 1e-4.
// Once without a viewer and once with one inside the box (the view bias).
TEST(VulkanProbeInterpolation, EqualsTheCpuStageOnAScrolledRelocatedGrid) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const Scene s = random_scene(17);
  const probes::InterpolationSettings settings;
  engine::math::Pcg32 rng(3, 9);
  const int n = 3000;
  std::vector<glm::vec3> pos(n), nrm(n);
  for (int i = 0; i < n; ++i) {
    pos[static_cast<std::size_t>(i)] = glm::mix(s.grid.min - 0.5f, s.grid.max + 0.5f, glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()));
    glm::vec3 d(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
    nrm[static_cast<std::size_t>(i)] = glm::normalize(d + glm::vec3(1e-3f));
  }
  gpu::VulkanProbeInterpolator interpolator(*ctx, s.layout);
  const glm::vec3 eye = glm::mix(s.grid.min, s.grid.max, glm::vec3(0.3f, 0.6f, 0.2f));
  for (const glm::vec3* viewer : {static_cast<const glm::vec3*>(nullptr), &eye}) {
    SCOPED_TRACE(viewer ? "with a viewer (the view bias)" : "without a viewer");
    const gpu::GpuInterpolation got = interpolator.interpolate(s.grid, s.states, s.sh, s.usable, settings, pos, nrm, viewer);
    ASSERT_EQ(got.results.size(), static_cast<std::size_t>(n));

    int flipped = 0, pruned_total = 0, fallbacks = 0, bad = 0;
    for (int i = 0; i < n; ++i) {
      const auto want = probes::interpolate_probes_reference(s.grid, s.layout, s.states, pos[static_cast<std::size_t>(i)],
                                                             nrm[static_cast<std::size_t>(i)], settings, s.usable, viewer);
      const auto& g = got.results[static_cast<std::size_t>(i)];
      pruned_total += want.pruned;
      fallbacks += want.fallback;
      if (want.probes != g.probes) {
        if (bad++ < 5) ADD_FAILURE() << "point " << i << ": the cage's probes differ (corner 0: expected " << want.probes[0] << ", got " << g.probes[0] << ")";
        continue;
      }
      if (want.pruned != g.pruned || want.fallback != g.fallback) {
        ++flipped;
        continue;
      }
      for (std::size_t c = 0; c < 8; ++c)
        if (!(std::abs(want.weights[c] - g.weights[c]) <= 1e-4f) && bad++ < 5)
          ADD_FAILURE() << "point " << i << " corner " << c << ": expected weight " << want.weights[c] << ", got " << g.weights[c];
      for (int k = 0; k < 75; ++k) {
        double l = 0;
        for (std::size_t c = 0; c < 8; ++c) l += want.weights[c] * s.sh[static_cast<std::size_t>(want.probes[c]) * 75 + k];
        const float gk = got.light_sh[static_cast<std::size_t>(i) * 75 + k];
        if (!(std::abs(gk - l) <= 1e-4) && bad++ < 5)
          ADD_FAILURE() << "point " << i << " SH " << k << ": expected " << l << ", got " << gk;
      }
    }
    std::printf("interpolation %s: %d points, %d corners pruned, %d fallbacks, %d decisions flipped\n",
                viewer ? "with a viewer" : "without a viewer", n, pruned_total, fallbacks, flipped);
    EXPECT_EQ(bad, 0);
    EXPECT_LE(flipped, n / 200) << "pruning decisions that differ from the CPU";
    EXPECT_GT(pruned_total, n) << "the scene should exercise pruning";
    EXPECT_GT(fallbacks, 0) << "the scene should exercise the fallback";
  }
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Known answer: a point on a probe's grid point (no offsets, nothing
// occluded, normal towards the probe) takes that probe's SH alone.
TEST(VulkanProbeInterpolation, APointOnAProbeTakesThatProbesLightAlone) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  Scene s = random_scene(4);
  s.grid.offsets.clear();
  std::fill(s.usable.begin(), s.usable.end(), std::uint8_t{1});
  for (auto& st : s.states) st.depth.reset(s.layout.texel_count(), 1.0f);  // never hit: all visible
  const glm::ivec3 c(2, 1, 3);
  const glm::vec3 p = s.grid.min + glm::vec3(c) * s.grid.spacing();
  const int q = s.grid.index(c);
  const std::vector<glm::vec3> pos = {p}, nrm = {glm::vec3(0, 1, 0)};
  gpu::VulkanProbeInterpolator interpolator(*ctx, s.layout);
  const auto got = interpolator.interpolate(s.grid, s.states, s.sh, s.usable, probes::InterpolationSettings{}, pos, nrm);
  for (int k = 0; k < 75; ++k)
    EXPECT_NEAR(got.light_sh[static_cast<std::size_t>(k)], s.sh[static_cast<std::size_t>(q) * 75 + k], 1e-5) << "coefficient " << k;
}
