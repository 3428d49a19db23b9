// The Vulkan kernels against their CPU stages in one process (issue 12).
// On this machine the device is lavapipe (Mesa's CPU driver), so these
// numbers say what the shader path costs where there is no GPU, not what a
// GPU does. Counter gpu_ms is the kernel's own time (timestamps); the wall
// time adds the uploads and downloads. Skips, with the reason, where no
// Vulkan device can be created.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "engine/gpu/vulkan_context.h"
#include "engine/jobs/job_system.h"
#include "engine/math/rng.h"
#include "gpu/vulkan_fused_decoder.h"
#include "gpu/vulkan_sh_projector.h"
#include "shading/fused_decoder.h"

namespace {

engine::gpu::VulkanContext* context(std::string* why_out) {
  static std::string why;
  static std::unique_ptr<engine::gpu::VulkanContext> ctx = [] {
    engine::gpu::GpuOptions o;
    o.validation = false;
    auto c = engine::gpu::VulkanContext::create(o, &why);
    if (c) std::printf("Vulkan device: %s (%s)\n", c->info().name.c_str(), c->info().driver.c_str());
    return c;
  }();
  *why_out = why;
  return ctx.get();
}

// The half-resolution GI of a 640x360 frame: 320 x 180 decoded points.
constexpr int kPoints = 320 * 180;
// Every pixel of a 1920 x 1080 frame, the paper's "Network Inference" row
// (Table 4); run on the Vulkan kernel only (a GPU's size).
constexpr int kPoints1080p = 1920 * 1080;

struct Batch {
  transgi::model::Mlp mlp{transgi::model::MlpLayout{}};
  std::vector<float> inputs, light, rgb;
  explicit Batch(int points) {
    mlp.initialise(3);
    engine::math::Pcg32 rng(1, 2);
    inputs.resize(static_cast<std::size_t>(points) * 16);
    light.resize(static_cast<std::size_t>(points) * 75);
    rgb.resize(static_cast<std::size_t>(points) * 3);
    for (float& x : inputs) x = rng.next_float() - 0.5f;
    for (float& x : light) x = rng.next_float() - 0.3f;
  }
};

// Arg 0: the CPU's fastest fused backend on one core; 1: the Vulkan
// per-point kernel; 2: the Vulkan tiled kernel. Arg 1: the points.
void BM_FusedInference(benchmark::State& state) {
  static Batch small(kPoints);
  static std::unique_ptr<Batch> large;
  const int points = static_cast<int>(state.range(1));
  if (points != kPoints && !large) large = std::make_unique<Batch>(points);
  Batch& b = points == kPoints ? small : *large;
  if (state.range(0) >= 1) {
    std::string why;
    auto* ctx = context(&why);
    if (!ctx) return state.SkipWithError(("no Vulkan device: " + why).c_str());
    const auto kernel = state.range(0) == 2 ? transgi::gpu::FusedKernel::Tiled : transgi::gpu::FusedKernel::PerPoint;
    transgi::gpu::VulkanFusedDecoder gpu(*ctx, b.mlp, transgi::gpu::FusedWeights::Auto, kernel);
    state.SetLabel(kernel == transgi::gpu::FusedKernel::Tiled ? "tiled" : "per-point");
    double gpu_ms = 0;
    for (auto _ : state) gpu_ms += gpu.shade(b.inputs, b.light, b.rgb);
    state.counters["gpu_ms"] = gpu_ms / static_cast<double>(state.iterations());
  } else {
    const transgi::shading::FusedDecoder cpu(b.mlp);
    state.SetLabel(transgi::shading::fused_isa_name(cpu.isa()));
    for (auto _ : state)
      for (int i = 0; i < kPoints; i += transgi::shading::kFusedTile)
        cpu.shade_tile(b.inputs.data() + static_cast<std::size_t>(i) * 16, b.light.data() + static_cast<std::size_t>(i) * 75,
                       std::min(transgi::shading::kFusedTile, kPoints - i), b.rgb.data() + static_cast<std::size_t>(i) * 3);
  }
  state.SetItemsProcessed(state.iterations() * points);
}

// 192 probes (the real-time budget) of 50 x 25 maps. Arg 0: MapProjector
// on one core; 1: the Vulkan kernel.
void BM_ShProjection(benchmark::State& state) {
  const transgi::probes::MapProjector projector(transgi::probes::MapLayout{50, 25});
  const int probes = 192, texels = projector.layout().texel_count();
  std::vector<glm::vec3> maps(static_cast<std::size_t>(probes) * texels, glm::vec3(0.5f, 0.4f, 0.3f));
  std::vector<float> out(static_cast<std::size_t>(probes) * 75);
  if (state.range(0) >= 1) {
    std::string why;
    auto* ctx = context(&why);
    if (!ctx) return state.SkipWithError(("no Vulkan device: " + why).c_str());
    transgi::gpu::VulkanShProjector gpu(*ctx, projector);
    double gpu_ms = 0;
    for (auto _ : state) gpu_ms += gpu.project(maps, out);
    state.counters["gpu_ms"] = gpu_ms / static_cast<double>(state.iterations());
  } else {
    for (auto _ : state)
      for (int q = 0; q < probes; ++q)
        projector.project(maps.data() + static_cast<std::size_t>(q) * texels, out.data() + static_cast<std::size_t>(q) * 75);
  }
  state.SetItemsProcessed(state.iterations() * probes);
}

}  // namespace

BENCHMARK(BM_FusedInference)
    ->Args({0, kPoints})
    ->Args({1, kPoints})
    ->Args({2, kPoints})
    ->Args({0, kPoints})
    ->Args({1, kPoints})
    ->Args({2, kPoints})
    ->Args({1, kPoints1080p})
    ->Args({2, kPoints1080p})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ShProjection)->Arg(0)->Arg(1)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
