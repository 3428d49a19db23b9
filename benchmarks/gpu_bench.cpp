// The Vulkan kernels against their CPU stages in one process (issue 12).
// On this machine the device is lavapipe (Mesa's CPU driver), so these
// numbers say what the shader path costs where there is no GPU, not what a
// GPU does. Counter gpu_ms is the kernel's own time (timestamps); the wall
// time adds the uploads and downloads. Skips, with the reason, where no
// Vulkan device can be created.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "engine/app/app.h"
#include "engine/gpu/gpu_rt_scene.h"
#include "engine/gpu/visibility_pass.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/render/camera_rays.h"
#include "engine/rt/rt_scene.h"
#include "engine/jobs/job_system.h"
#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "eval/method_runs.h"
#include "gpu/vulkan_fused_decoder.h"
#include "gpu/vulkan_sh_projector.h"
#include "shading/fused_decoder.h"

namespace {

namespace eval_scene {
// The sample level, loaded once (its Embree mirror synced): from the
// working directory's content/ where there is one (a packed run on another
// machine), else from the source tree this was built from.
std::string level_path() {
  const std::string relative = "content/levels/living_room/scene.gltf";
  return std::filesystem::exists(relative) ? relative : std::string(TRANSGI_LEVEL_SCENE);
}

class Holder {
 public:
  Holder() : scene_(transgi::eval::load_scene(level_path(), "", 2)) {}
  engine::app::App& app() { return *scene_.app; }
  const engine::rt::RtScene& rt() { return scene_.app->world().resource<engine::rt::RtScene>(); }
  engine::render::CameraRays camera(int width, int height) {
    auto& w = scene_.app->world();
    return {w.get<engine::scene::Camera>(scene_.camera), w.get<engine::transform::WorldTransform>(scene_.camera), width, height};
  }
  float near_plane() { return scene_.app->world().get<engine::scene::Camera>(scene_.camera).znear; }

 private:
  transgi::eval::LoadedScene scene_;
};
}  // namespace eval_scene

// RayQuery: true where the device has VK_KHR_ray_query (the default a
// frame gets); false: the compute-shader BVH traversal.
template <bool RayQuery = true>
engine::gpu::VulkanContext* context(std::string* why_out) {
  static std::string why;
  static std::unique_ptr<engine::gpu::VulkanContext> ctx = [] {
    engine::gpu::GpuOptions o;
    o.validation = false;
    o.ray_query = RayQuery;
    auto c = engine::gpu::VulkanContext::create(o, &why);
    if (c) std::printf("Vulkan device: %s\n", engine::gpu::describe(c->info()).c_str());
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

// Incoherent rays (probe rays' kind) through the sample level: 65,536 rays
// from random points in its bounds in random directions. Arg 0: Embree, one
// ray at a time over the job system (the CPU backend); 1: the compute-shader
// BVH traversal; 2: VK_KHR_ray_query (skipped where the device has none).
// Counter hits: rays that hit, which must agree across the three.
void BM_RayTraversal(benchmark::State& state) {
  static eval_scene::Holder level;
  const engine::rt::RtScene& rt = level.rt();
  static const std::vector<engine::rt::Ray> rays = [&] {
    engine::math::Pcg32 rng(9, 9);
    std::vector<engine::rt::Ray> out(65536);
    const glm::vec3 lo = rt.bounds_min(), hi = rt.bounds_max();
    for (auto& r : out) {
      r.origin = lo + (hi - lo) * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
      const float z = 2.0f * rng.next_float() - 1.0f, phi = 6.2831853f * rng.next_float();
      const float sxy = std::sqrt(std::max(0.0f, 1.0f - z * z));
      r.direction = {sxy * std::cos(phi), sxy * std::sin(phi), z};
    }
    return out;
  }();
  std::vector<engine::rt::Hit> hits(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  if (state.range(0) == 0) {
    state.SetLabel("embree");
    for (auto _ : state)
      level.app().jobs().run([&] {
        engine::jobs::parallel_for<std::size_t>(0, rays.size(), 1024, [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i) found[i] = rt.intersect(rays[i], hits[i]) ? 1 : 0;
        });
      });
  } else {
    std::string why;
    auto* ctx = state.range(0) == 2 ? context<true>(&why) : context<false>(&why);
    if (!ctx) return state.SkipWithError(("no Vulkan device: " + why).c_str());
    if (state.range(0) == 2 && !ctx->info().ray_query) return state.SkipWithError("the device has no VK_KHR_ray_query");
    state.SetLabel(ctx->info().ray_query ? "ray query" : "compute BVH");
    engine::gpu::GpuRtScene gpu(*ctx);
    gpu.sync(rt);
    double gpu_ms = 0;
    for (auto _ : state) {
      double ms = 0;
      level.app().jobs().run([&] { gpu.intersect(rays, hits, found, &ms); });
      gpu_ms += ms;
    }
    state.counters["gpu_ms"] = gpu_ms / static_cast<double>(state.iterations());
  }
  std::size_t n_hits = 0;
  for (const std::uint8_t f : found) n_hits += f;
  state.counters["hits"] = static_cast<double>(n_hits);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rays.size()));
}

// Primary visibility of the sample level's camera at range(1) x 9/16 of it.
// Arg 0: the camera rays made on the host and traced by the GPU
// (GpuRtScene::intersect with ray queries, as the Vulkan G-buffer traces
// them today); 1: the raster visibility pass and its resolve
// (VisibilityPass), which sends no rays. Counter gpu_ms: the device's time;
// hits must agree.
void BM_PrimaryVisibility(benchmark::State& state) {
  static eval_scene::Holder level;
  const int width = static_cast<int>(state.range(1)), height = width * 9 / 16;
  const engine::render::CameraRays camera = level.camera(width, height);
  std::string why;
  auto* ctx = context<true>(&why);
  if (!ctx) return state.SkipWithError(("no Vulkan device: " + why).c_str());
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<engine::rt::Hit> hits(n);
  std::vector<std::uint8_t> found(n);
  engine::gpu::GpuRtScene gpu(*ctx);
  gpu.sync(level.rt());
  double gpu_ms = 0;
  if (state.range(0) == 0) {
    state.SetLabel(ctx->info().ray_query ? "camera rays, ray query" : "camera rays, compute BVH");
    std::vector<engine::rt::Ray> rays(n);
    for (auto _ : state) {
      double ms = 0;
      level.app().jobs().run([&] {
        engine::jobs::parallel_for<std::size_t>(0, n, 4096, [&](std::size_t b, std::size_t e) {
          for (std::size_t i = b; i < e; ++i)
            rays[i] = camera.generate(glm::vec2(static_cast<float>(i % static_cast<std::size_t>(width)) + 0.5f,
                                                static_cast<float>(i / static_cast<std::size_t>(width)) + 0.5f));
        });
        gpu.intersect(rays, hits, found, &ms);
      });
      gpu_ms += ms;
    }
  } else {
    if (!engine::gpu::VisibilityPass::supported(*ctx, &why)) return state.SkipWithError(why.c_str());
    state.SetLabel("raster visibility pass");
    engine::gpu::VisibilityPass pass(*ctx);
    for (auto _ : state) {
      double ms = 0;
      pass.render(gpu, camera, {0.5f, 0.5f}, level.near_plane(), hits, found, &ms);
      gpu_ms += ms;
    }
  }
  state.counters["gpu_ms"] = gpu_ms / static_cast<double>(state.iterations());
  std::size_t n_hits = 0;
  for (const std::uint8_t f : found) n_hits += f;
  state.counters["hits"] = static_cast<double>(n_hits);
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}

}  // namespace

BENCHMARK(BM_PrimaryVisibility)
    ->Args({0, 640})
    ->Args({1, 640})
    ->Args({0, 1920})
    ->Args({1, 1920})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RayTraversal)->Arg(0)->Arg(1)->Arg(2)->Arg(0)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);
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
