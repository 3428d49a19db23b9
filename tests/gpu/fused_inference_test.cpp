// shaders/fused_inference.comp against its CPU stage (shading::FusedDecoder,
// scalar backend) on the same inputs, and against a known answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/math/rng.h"
#include "gpu/vulkan_fused_decoder.h"
#include "gpu_fixture.h"
#include "shading/fused_decoder.h"

using namespace transgi;

namespace {

// Every layer at He scale (initialise() keeps the output layer tiny, which
// would let a wrong kernel pass).
model::Mlp random_mlp(std::uint64_t seed) {
  model::Mlp mlp(model::MlpLayout{});
  const auto& lay = mlp.layout();
  engine::math::Pcg32 rng(seed, 7);
  for (int l = 0; l < lay.layer_count(); ++l) {
    const float bound = std::sqrt(6.0f / static_cast<float>(lay.in_of(l)));
    float* w = mlp.params().data() + lay.weight_offset(l);
    for (int i = 0; i < lay.out_of(l) * lay.in_of(l); ++i) w[i] = bound * (2 * rng.next_float() - 1);
    float* b = mlp.params().data() + lay.bias_offset(l);
    for (int i = 0; i < lay.out_of(l); ++i) b[i] = 0.1f * (2 * rng.next_float() - 1);
  }
  return mlp;
}

std::vector<float> cpu_shade(const model::Mlp& mlp, const std::vector<float>& inputs, const std::vector<float>& light,
                             int n) {
  const shading::FusedDecoder cpu(mlp, shading::FusedIsa::Scalar);
  std::vector<float> rgb(static_cast<std::size_t>(n) * 3);
  for (int i0 = 0; i0 < n; i0 += shading::kFusedTile) {
    const int m = std::min(shading::kFusedTile, n - i0);
    cpu.shade_tile(inputs.data() + static_cast<std::size_t>(i0) * 16, light.data() + static_cast<std::size_t>(i0) * 75, m,
                   rgb.data() + static_cast<std::size_t>(i0) * 3);
  }
  return rgb;
}

}  // namespace

// 333 points: five full workgroups and a partial one, so idle lanes and the
// tail are exercised. Both sides are fp32 with a different summation order;
// 1e-4 of the batch's largest value bounds that (measured: ~1e-6).
TEST(VulkanFusedInference, EqualsTheCpuScalarStageOnRandomPoints) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const int n = 333;
  const model::Mlp mlp = random_mlp(42);
  engine::math::Pcg32 rng(9, 3);
  std::vector<float> inputs(static_cast<std::size_t>(n) * 16), light(static_cast<std::size_t>(n) * 75);
  for (float& x : inputs) x = 2 * rng.next_float() - 1;
  for (std::size_t i = 0; i < light.size(); ++i) light[i] = (i % 25 == 0 ? 1.0f : 0.3f) * (2 * rng.next_float() - 0.5f);

  const std::vector<float> want = cpu_shade(mlp, inputs, light, n);
  gpu::VulkanFusedDecoder gpu_decoder(*ctx, mlp);
  std::vector<float> got(want.size(), -7.0f);
  gpu_decoder.shade(inputs, light, got);

  float scale = 0.0f;
  for (float v : want) scale = std::max(scale, std::abs(v));
  ASSERT_GT(scale, 0.1f) << "a degenerate batch would prove nothing";
  const float tolerance = 1e-4f * scale;
  int bad = 0;
  float worst = 0.0f;
  for (std::size_t i = 0; i < want.size(); ++i) {
    const float err = std::abs(got[i] - want[i]);
    worst = std::max(worst, err);
    if (!(err <= tolerance) && bad++ < 5)
      ADD_FAILURE() << "point " << i / 3 << " channel " << i % 3 << ": expected " << want[i] << ", got " << got[i]
                    << " (tolerance " << tolerance << ")";
  }
  EXPECT_EQ(bad, 0) << "worst error " << worst;
  RecordProperty("worst_abs_error", std::to_string(worst));
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Known answer: all weights zero, output biases 1, so every transfer
// coefficient is 1 and each channel is the sum of that channel's 25 light
// coefficients; hidden biases of -1 check that ReLU clamps.
TEST(VulkanFusedInference, UnitTransferSumsTheLightPerChannel) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  model::Mlp mlp(model::MlpLayout{});
  const auto& lay = mlp.layout();
  std::fill(mlp.params().begin(), mlp.params().end(), 0.0f);
  for (int l = 0; l < lay.layer_count(); ++l)
    for (int o = 0; o < lay.out_of(l); ++o)
      mlp.params()[lay.bias_offset(l) + static_cast<std::size_t>(o)] = l == lay.hidden_layers ? 1.0f : -1.0f;
  const int n = 70;
  std::vector<float> inputs(static_cast<std::size_t>(n) * 16, 0.5f), light(static_cast<std::size_t>(n) * 75);
  for (std::size_t i = 0; i < light.size(); ++i) light[i] = static_cast<float>(i % 75) * 0.01f + static_cast<float>(i / 75) * 0.001f;
  gpu::VulkanFusedDecoder gpu_decoder(*ctx, mlp);
  std::vector<float> rgb(static_cast<std::size_t>(n) * 3);
  gpu_decoder.shade(inputs, light, rgb);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      double want = 0;
      for (int k = 0; k < 25; ++k) want += light[static_cast<std::size_t>(i) * 75 + static_cast<std::size_t>(c) * 25 + k];
      EXPECT_NEAR(rgb[static_cast<std::size_t>(i) * 3 + c], want, 1e-5 * want) << "point " << i << " channel " << c;
    }
}

TEST(VulkanFusedInference, RefusesALayoutWiderThanTheKernelHoldsAndMismatchedSizes) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  model::MlpLayout wide;
  wide.width = 256;
  EXPECT_THROW(gpu::VulkanFusedDecoder(*ctx, model::Mlp(wide)), std::invalid_argument);
  gpu::VulkanFusedDecoder ok(*ctx, model::Mlp(model::MlpLayout{}));
  std::vector<float> inputs(16), light(74), rgb(3);
  EXPECT_THROW(ok.shade(inputs, light, rgb), std::invalid_argument);
}
