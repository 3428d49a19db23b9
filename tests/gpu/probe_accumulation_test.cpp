// shaders/probe_accumulation.comp against probes::accumulate and
// probes::filled_radiance (its CPU stages) on probes in every state the
// frame loop meets: cold (the warm-up ramp), settled with a known noise,
// hit by a change of light (the fast blend, holes refilled), rescaled by a
// brighter frame, and with holes that four dilation passes cannot reach
// (the mean fill).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/math/rng.h"
#include "gpu/vulkan_probe_accumulator.h"
#include "gpu_fixture.h"

using namespace transgi;

namespace {

struct Case {
  probes::ProbeMapState state;
  probes::FrameSamples frame;
};

// Probe i of the batch: its history, then one frame of samples.
Case make_case(int i, const probes::MapLayout& layout, engine::math::Pcg32& rng) {
  const int texels = layout.texel_count();
  Case c;
  c.state.reset(texels);
  const int kind = i % 5;
  // A smooth map of light, different per probe.
  const auto light = [&](int t, float gain) {
    const glm::vec3 d = layout.direction_of(t);
    return gain * glm::vec3(0.6f + 0.4f * d.y, 0.5f + 0.3f * d.x, 0.4f + 0.2f * d.z) * (1.0f + 0.1f * static_cast<float>(i % 7));
  };
  if (kind != 0) {
    // A settled history: most texels sampled, the noise measured.
    c.state.frames = 40 + i;
    c.state.noise_frames = 20;
    c.state.noise_variance = 1e-4f;
    c.state.stable_frames = 5;
    c.state.drift = 0.001f * static_cast<float>(i % 3 - 1);
    for (int t = 0; t < texels; ++t) {
      if (kind == 4 && t % 211 != 0) continue;  // sparse: holes beyond four dilation passes
      c.state.set_radiance(static_cast<std::size_t>(t), light(t, 1.0f));
      c.state.sampled[static_cast<std::size_t>(t)] = 1;
    }
  } else {
    c.state.frames = i % 3;  // cold: the warm-up ramp
  }
  c.frame.reset(texels);
  // Gains: steady (with noise), a change of light, a frame far brighter (rescale).
  const float gain = kind == 2 ? 1.6f : kind == 3 ? 60000.0f : 1.0f;
  for (int t = 0; t < texels; ++t) {
    if (rng.next_float() < (kind == 4 ? 0.995f : 0.3f)) continue;  // no sample here this frame
    const float count = static_cast<float>(1 + static_cast<int>(rng.next_float() * 3));
    const float noise = 1.0f + 0.05f * (rng.next_float() - 0.5f);
    c.frame.sum[static_cast<std::size_t>(t)] = light(t, gain) * noise * count;
    c.frame.count[static_cast<std::size_t>(t)] = count;
  }
  return c;
}

}  // namespace

// Every history texel's binary16 bits equal (both use Giesen's rounding; at
// most 0.1 % may differ by one ulp, where the float sums of a blend round
// otherwise), the sampled flags, the change decisions and the counters
// equal, the noise and drift to the precision of the change groups' sums
// (see below), and the filled maps to 1e-3 relative.
TEST(VulkanProbeAccumulation, EqualsTheCpuStagesInEveryStateOfTheFrameLoop) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const probes::MapLayout layout{40, 20};
  const probes::AccumulationSettings settings;
  engine::math::Pcg32 rng(17, 3);
  const int n = 40;
  std::vector<Case> gpu_cases, cpu_cases;
  for (int i = 0; i < n; ++i) gpu_cases.push_back(make_case(i, layout, rng));
  cpu_cases = gpu_cases;

  std::vector<probes::ProbeMapState*> states;
  std::vector<const probes::FrameSamples*> frames;
  for (Case& c : gpu_cases) {
    states.push_back(&c.state);
    frames.push_back(&c.frame);
  }
  const std::size_t texels = static_cast<std::size_t>(layout.texel_count());
  std::vector<std::uint8_t> changed(n);
  std::vector<glm::vec3> filled(n * texels);
  gpu::VulkanProbeAccumulator accumulator(*ctx, layout);
  accumulator.accumulate(states, frames, settings, changed, filled);

  int changes = 0, rescaled = 0, ulp_off = 0, bits_off = 0, flags_off = 0, decisions_off = 0, filled_off = 0;
  std::size_t holes = 0;
  for (int i = 0; i < n; ++i) {
    Case& want = cpu_cases[static_cast<std::size_t>(i)];
    const float scale_before = want.state.radiance_scale;
    const bool want_changed = probes::accumulate(want.state, want.frame, settings);
    const std::vector<glm::vec3> want_filled = probes::filled_radiance(want.state, layout, settings.fill_passes);
    const probes::ProbeMapState& got = gpu_cases[static_cast<std::size_t>(i)].state;
    changes += want_changed;
    rescaled += want.state.radiance_scale != scale_before;
    decisions_off += want_changed != (changed[static_cast<std::size_t>(i)] != 0);
    EXPECT_EQ(got.radiance_scale, want.state.radiance_scale) << "probe " << i;
    EXPECT_EQ(got.frames, want.state.frames) << "probe " << i;
    EXPECT_EQ(got.noise_frames, want.state.noise_frames) << "probe " << i;
    EXPECT_EQ(got.stable_frames, want.state.stable_frames) << "probe " << i;
    // The relative change is a small difference of two sums (float on the
    // device, double on the CPU): 1e-7 of a sum is 1e-4 of a 0.1 % change.
    EXPECT_NEAR(got.noise_variance, want.state.noise_variance, 1e-3 * want.state.noise_variance + 1e-9) << "probe " << i;
    EXPECT_NEAR(got.drift, want.state.drift, 1e-6 + 1e-6 * std::abs(want.state.drift)) << "probe " << i;
    for (std::size_t t = 0; t < texels; ++t) {
      holes += want.state.sampled[t] == 0;
      flags_off += got.sampled[t] != want.state.sampled[t];
      const std::uint16_t g[3] = {got.radiance[t].r, got.radiance[t].g, got.radiance[t].b};
      const std::uint16_t w[3] = {want.state.radiance[t].r, want.state.radiance[t].g, want.state.radiance[t].b};
      for (int k = 0; k < 3; ++k) {
        const int d = std::abs(static_cast<int>(g[k]) - static_cast<int>(w[k]));
        ulp_off += d == 1;
        bits_off += d > 1;
      }
      const glm::vec3 a = filled[static_cast<std::size_t>(i) * texels + t], b = want_filled[t];
      for (int k = 0; k < 3; ++k)
        if (std::abs(a[k] - b[k]) > 1e-3f * std::abs(b[k]) + 1e-6f) ++filled_off;
    }
  }
  std::printf("accumulation: %d probes, %d changes of light, %d rescaled, %zu holes after; %d values one ulp off, %d more, "
              "%d flags, %d decisions, %d filled values differ\n",
              n, changes, rescaled, holes, ulp_off, bits_off, flags_off, decisions_off, filled_off);
  ASSERT_GT(changes, 0) << "some probe should detect the change of light";
  ASSERT_GT(rescaled, 0) << "some probe should be rescaled";
  ASSERT_GT(holes, texels) << "some holes should need filling";
  EXPECT_EQ(bits_off, 0);
  EXPECT_LE(ulp_off, static_cast<int>(n * texels * 3 / 1000));
  EXPECT_EQ(flags_off, 0);
  EXPECT_EQ(decisions_off, 0);
  EXPECT_LE(filled_off, static_cast<int>(n * texels * 3 / 1000)) << "filled values beyond 1e-3 of the CPU's";
}
