// shaders/sh_projection.comp against probes::MapProjector (its CPU stage) and
// against a known answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "gpu/vulkan_sh_projector.h"
#include "gpu_fixture.h"

using namespace transgi;

// Five probes of random radiance on the default 100 x 50 maps. The CPU sums
// rows in double, the GPU in fp32 over 32 strided partial sums of 156-157
// texels: 1e-4 of the largest coefficient bounds the difference (measured
// below 1e-6).
TEST(VulkanShProjection, EqualsTheCpuProjectorOnRandomMaps) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const probes::MapProjector cpu(probes::MapLayout{});
  const int texels = cpu.layout().texel_count(), probes_n = 5;
  engine::math::Pcg32 rng(5, 1);
  std::vector<glm::vec3> radiance(static_cast<std::size_t>(texels) * probes_n);
  for (auto& l : radiance) l = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * (rng.next_float() < 0.01f ? 50.0f : 1.0f);
  std::vector<float> want(static_cast<std::size_t>(probes_n) * 75), got(want.size(), -1.0f);
  for (int q = 0; q < probes_n; ++q)
    cpu.project(radiance.data() + static_cast<std::size_t>(q) * texels, want.data() + static_cast<std::size_t>(q) * 75);
  gpu::VulkanShProjector projector(*ctx, cpu);
  projector.project(radiance, got);
  float scale = 0;
  for (float v : want) scale = std::max(scale, std::abs(v));
  int bad = 0;
  for (std::size_t i = 0; i < want.size(); ++i)
    if (!(std::abs(got[i] - want[i]) <= 1e-4f * scale) && bad++ < 5)
      ADD_FAILURE() << "probe " << i / 75 << " coefficient " << i % 75 << ": expected " << want[i] << ", got " << got[i]
                    << " (tolerance " << 1e-4f * scale << ")";
  EXPECT_EQ(bad, 0);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// A furnace: a map of constant radiance 1 projects to 2 sqrt(pi) in the DC
// term (integral of Y_00 = 1 / (2 sqrt(pi)) over 4 pi sr) and 0 elsewhere.
// The per-texel basis integrals are 4 x 4-point quadratures in azimuth, so
// the higher bands cancel to about 2e-5 of the DC term, not exactly: the
// tolerance is 1e-4 of each channel's DC.
TEST(VulkanShProjection, AUniformMapIsPureDcOfTwoRootPi) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const probes::MapProjector cpu(probes::MapLayout{});
  std::vector<glm::vec3> radiance(static_cast<std::size_t>(cpu.layout().texel_count()), glm::vec3(1.0f, 2.0f, 0.5f));
  std::vector<float> got(75);
  gpu::VulkanShProjector(*ctx, cpu).project(radiance, got);
  const float dc = 2.0f * std::sqrt(engine::math::kPi);
  const float channel[3] = {1.0f, 2.0f, 0.5f};
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(got[static_cast<std::size_t>(c) * 25], dc * channel[c], 1e-4 * dc * channel[c]) << "channel " << c;
    for (int k = 1; k < 25; ++k) EXPECT_NEAR(got[static_cast<std::size_t>(c) * 25 + k], 0.0f, 1e-4 * dc * channel[c]) << "channel " << c << " k " << k;
  }
}
