// Decoder throughput: forward (inference) and forward+backward (training) at
// batch 2048 on the oneDNN backend, and a whole Trainer::step() on a small
// dataset; the counters report samples/s and GFLOP/s so the share of time
// spent outside the GEMMs is visible (docs/bake.md).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include <filesystem>
#include <string>

#include "bake/trainer.h"
#include "engine/app/app.h"
#include "engine/render/camera_rays.h"
#include "eval/method_runs.h"
#include "shading/gbuffer.h"
#include "engine/jobs/job_system.h"
#include "shading/fused_decoder.h"
#include "shading/transfer_inference.h"
#include "eval/machine_peak.h"
#include "engine/math/rng.h"
#include "probes/probe_grid.h"
#include "engine/scene/procedural.h"
#include "model/mlp.h"

using namespace transgi;

namespace {
constexpr int kBatch = 2048;

std::vector<float> random_inputs(std::size_t n) {
  engine::math::Pcg32 rng(1, 2);
  std::vector<float> v(n);
  for (float& x : v) x = 2 * rng.next_float() - 1;
  return v;
}

model::GemmBackend backend_of(const benchmark::State& state) {
  return state.range(0) == 16 ? model::GemmBackend::OneDnnBf16 : model::GemmBackend::OneDnn;
}

void BM_DecoderForward(benchmark::State& state) {
  model::Mlp net(model::MlpLayout{});
  net.initialise(1);
  const auto x = random_inputs(static_cast<std::size_t>(kBatch) * 16);
  std::vector<float> y(static_cast<std::size_t>(kBatch) * 75);
  model::MlpWorkspace ws;
  for (auto _ : state) net.forward(x.data(), kBatch, y.data(), ws, backend_of(state));
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kBatch, benchmark::Counter::kIsRate);
  state.counters["GFLOP/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kBatch * 88832.0 * 1e-9, benchmark::Counter::kIsRate);
}

void BM_DecoderForwardBackward(benchmark::State& state) {
  model::Mlp net(model::MlpLayout{});
  net.initialise(1);
  const auto x = random_inputs(static_cast<std::size_t>(kBatch) * 16);
  const auto dy = random_inputs(static_cast<std::size_t>(kBatch) * 75);
  std::vector<float> y(dy.size()), grad(net.params().size()), dx(x.size());
  model::MlpWorkspace ws;
  for (auto _ : state) {
    net.forward(x.data(), kBatch, y.data(), ws, backend_of(state));
    net.backward(x.data(), kBatch, dy.data(), ws, grad, dx.data(), backend_of(state));
  }
  // backward ~ 2x forward FLOPs
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kBatch, benchmark::Counter::kIsRate);
  state.counters["GFLOP/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kBatch * 3 * 88832.0 * 1e-9, benchmark::Counter::kIsRate);
}

void BM_TrainerStep(benchmark::State& state) {
  engine::scene::SceneAssets a;
  a.generation = engine::scene::next_scene_generation();
  a.meshes = {std::make_shared<engine::scene::MeshAsset>(engine::scene::make_uv_sphere(1, 64, 32))};
  a.materials.resize(1);
  bake::DatasetSettings ds;
  ds.points = 2000;
  ds.rays = 32;
  const auto data = bake::generate_dataset(a, ds);
  auto m = bake::make_untrained_model(a, 7, model::MlpLayout{}, 1);
  bake::TrainSettings ts;
  ts.backend = backend_of(state);
  ts.gradient_blocks = static_cast<int>(state.range(1));
  bake::Trainer trainer(data, a, m, ts);
  for (auto _ : state) trainer.step();
  state.counters["samples/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kBatch, benchmark::Counter::kIsRate);
}
// A training step against the size of the level's latent table (docs/bake.md,
// "Scaling"): the same batch of 2048 on a sphere of `range(0)` x 1000
// vertices. With every latent updated (range(1) = 0, the default), zeroing
// the gradients, the finiteness check and the dense Adam update touch every
// latent every step, on every rank of a distributed bake; with only the
// touched rows (range(1) = 1) the step should not grow with the table.
void BM_TrainerStepByLatentTable(benchmark::State& state) {
  const int segments = static_cast<int>(std::lround(std::sqrt(static_cast<double>(state.range(0)) * 1000.0 / 2.0)));
  engine::scene::SceneAssets a;
  a.generation = engine::scene::next_scene_generation();
  a.meshes = {std::make_shared<engine::scene::MeshAsset>(engine::scene::make_uv_sphere(1, 2 * segments, segments))};
  a.materials.resize(1);
  bake::DatasetSettings ds;
  ds.points = 2000;
  ds.rays = 16;
  ds.max_points_per_vertex = 0;
  const auto data = bake::generate_dataset(a, ds);
  auto m = bake::make_untrained_model(a, 7, model::MlpLayout{}, 1);
  bake::TrainSettings ts;
  ts.latent_updates = state.range(1) ? bake::LatentUpdates::Touched : bake::LatentUpdates::All;
  bake::Trainer trainer(data, a, m, ts);
  for (auto _ : state) trainer.step();
  state.counters["latent floats"] = static_cast<double>(m.meshes[0].latents.values.size());
}
BENCHMARK(BM_TrainerStepByLatentTable)->ArgsProduct({{10, 1000, 4000}, {0, 1}})->Unit(benchmark::kMillisecond);

// Per-pixel transfer: the batched path the renderer uses (arg 1) against the
// scalar reference it is tested against (arg 0), on 8192 queries.
void BM_InferTransfer(benchmark::State& state) {
  engine::scene::SceneAssets a;
  a.generation = engine::scene::next_scene_generation();
  a.meshes = {std::make_shared<engine::scene::MeshAsset>(engine::scene::make_uv_sphere(1, 64, 32))};
  a.materials.resize(1);
  auto m = bake::make_untrained_model(a, 7, model::MlpLayout{}, 1);
  engine::math::Pcg32 rng(3, 4);
  std::vector<shading::TransferQuery> q(8192);
  for (auto& x : q) {
    x.triangle = static_cast<std::uint32_t>(rng.next_float() * 1000.0f);
    x.barycentric = {0.3f, 0.3f};
    x.albedo = glm::vec3(0.5f);
    x.normal = {0, 0, 1};
    x.wo = glm::normalize(glm::vec3(0.2f, 0.1f, 1));
  }
  std::vector<float> out(q.size() * 75);
  engine::jobs::JobSystem jobs({.threads = 0});
  for (auto _ : state) {
    if (state.range(0) == 1) {
      jobs.run([&] { shading::infer_transfer(m, a, q, out.data()); });
    } else {
      for (std::size_t i = 0; i < q.size(); ++i) shading::infer_transfer_reference(m, a, q[i], out.data() + i * 75);
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["pixels/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * q.size(), benchmark::Counter::kIsRate);
}

// The machine's bf16 peak, measured here so every ratio is against the same
// clock and load (the loop is the one bench-frame uses).
void BM_Bf16Peak(benchmark::State& state) {
  if (!shading::cpu_supports(shading::FusedIsa::Avx512Bf16)) {
    state.SkipWithError("no AVX-512 BF16 on this CPU");
    return;
  }
  constexpr long long kReps = 1 << 20;
  for (auto _ : state) benchmark::DoNotOptimize(eval::bf16_peak_loop(kReps));
  state.counters["GFLOP/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kReps * 24 * 64 * 1e-9, benchmark::Counter::kIsRate);
}

// The tile unit's bf16 peak, measured the same way (register-only tile
// products), so the AMX kernel's share of it is a same-process ratio.
void BM_AmxPeak(benchmark::State& state) {
  if (!shading::cpu_supports(shading::FusedIsa::Amx)) {
    state.SkipWithError("no AMX on this CPU (or the OS refused the tile state)");
    return;
  }
  constexpr long long kReps = 1 << 16;
  for (auto _ : state) benchmark::DoNotOptimize(eval::amx_peak_loop(kReps));
  state.counters["GFLOP/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kReps * 4 * 16384 * 1e-9, benchmark::Counter::kIsRate);
}

// One frame's GI pixels at half of 640x360.
constexpr int kFramePixels = 320 * 180;

struct FusedBatch {
  model::Mlp net{model::MlpLayout{}};
  std::vector<float> inputs, light;
  FusedBatch() {
    net.initialise(1);
    inputs = random_inputs(static_cast<std::size_t>(kFramePixels) * 16);
    light = random_inputs(static_cast<std::size_t>(kFramePixels) * 75);
  }
};

// The fused kernel on a frame's pixels, tile after tile on each benchmark
// thread (arg: 3 = amx, 2 = avx512bf16, 1 = avx2, 0 = scalar). GFLOP/s counts the
// network's 88,832 FLOP per pixel.
void BM_FusedShade(benchmark::State& state) {
  const auto isa = static_cast<shading::FusedIsa>(state.range(0));
  if (!shading::cpu_supports(isa)) {
    state.SkipWithError("backend not supported by this CPU");
    return;
  }
  static const FusedBatch batch;
  const shading::FusedDecoder decoder(batch.net, isa);
  const int pixels = isa == shading::FusedIsa::Scalar ? kFramePixels / 64 : kFramePixels;
  std::vector<float> rgb(static_cast<std::size_t>(pixels) * 3);
  for (auto _ : state) {
    for (int b = 0; b < pixels; b += shading::kFusedTile)
      decoder.shade_tile(batch.inputs.data() + static_cast<std::size_t>(b) * 16, batch.light.data() + static_cast<std::size_t>(b) * 75,
                         std::min(shading::kFusedTile, pixels - b), rgb.data() + static_cast<std::size_t>(b) * 3);
    benchmark::DoNotOptimize(rgb.data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * pixels * 88832.0 * 1e-9, benchmark::Counter::kIsRate);
}

// oneDNN's bf16 matmul chain (one primitive per layer, bias and ReLU between
// them, 8192-row chunks as the batched renderer runs it) on the same pixels;
// the 75 outputs go to memory and the light dot is not even included.
void BM_OneDnnBf16Chain(benchmark::State& state) {
  static const FusedBatch batch;
  std::vector<float> y(static_cast<std::size_t>(kFramePixels) * 75);
  model::MlpWorkspace ws;
  for (auto _ : state) {
    for (int b = 0; b < kFramePixels; b += 8192)
      batch.net.forward(batch.inputs.data() + static_cast<std::size_t>(b) * 16, std::min(8192, kFramePixels - b),
                        y.data() + static_cast<std::size_t>(b) * 75, ws, model::GemmBackend::OneDnnBf16);
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["GFLOP/s"] = benchmark::Counter(static_cast<double>(state.iterations()) * kFramePixels * 88832.0 * 1e-9, benchmark::Counter::kIsRate);
}

}  // namespace

// ProbeGrid::cage against its reference on 4,096 points of an 8^3 grid
// (scrolled, relocated probes): Arg 0 = reference, 1 = the fast path.
void BM_ProbeCage(benchmark::State& state) {
  transgi::probes::ProbeGrid g{glm::vec3(-3.0f, 0.0f, -2.5f), glm::vec3(3.0f, 3.0f, 2.5f), glm::ivec3(8)};
  g.scroll_by(glm::ivec3(2, 1, 3));
  g.offsets.assign(static_cast<std::size_t>(g.count()), glm::vec3(0.01f));
  std::vector<glm::vec3> points(4096);
  engine::math::Pcg32 rng = engine::math::make_rng(3, 0, 0);
  for (auto& p : points) p = glm::mix(g.min, g.max, glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()));
  const bool fast = state.range(0) == 1;
  for (auto _ : state) {
    float sum = 0;
    for (const glm::vec3& p : points) {
      const auto c = fast ? g.cage(p) : g.cage_reference(p);
      sum += c.weights[3] + c.positions[5].y + static_cast<float>(c.probes[7]);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}

// The G-buffer's samples of the sample level's 640 x 360 view, its hits
// traced once beforehand, one thread: Arg 0 = make_gsample a pixel at a
// time (the oracle), 1 = make_gsamples a 4 x 4 tile at a time (the frame's).
void BM_GBufferSamples(benchmark::State& state) {
  const std::string relative = "content/levels/living_room/scene.gltf";
  const transgi::eval::LoadedScene scene =
      transgi::eval::load_scene(std::filesystem::exists(relative) ? relative : std::string(TRANSGI_LEVEL_SCENE), "", 1);
  const auto& w = scene.app->world();
  const auto& rt = w.resource<engine::rt::RtScene>();
  const auto& assets = w.resource<engine::scene::SceneAssets>();
  const int width = 640, height = 360, tiles_x = width / 4, tiles = tiles_x * (height / 4);
  const engine::render::CameraRays camera(w.get<engine::scene::Camera>(scene.camera), w.get<engine::transform::WorldTransform>(scene.camera),
                                          width, height);
  std::vector<engine::rt::Ray> rays(static_cast<std::size_t>(width) * height);
  std::vector<engine::rt::Hit> hits(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  for (int t = 0; t < tiles; ++t)
    for (int i = 0; i < 16; ++i) {
      const std::size_t k = static_cast<std::size_t>(t) * 16 + static_cast<std::size_t>(i);
      rays[k] = camera.generate({static_cast<float>(t % tiles_x * 4 + i % 4) + 0.5f, static_cast<float>(t / tiles_x * 4 + i / 4) + 0.5f});
      found[k] = rt.intersect(rays[k], hits[k]) ? 1 : 0;
    }
  std::vector<transgi::shading::GSample> samples(rays.size());
  const bool tile = state.range(0) == 1;
  const float spread = camera.pixel_spread();
  for (auto _ : state)
    for (int t = 0; t < tiles; ++t) {
      const std::size_t first = static_cast<std::size_t>(t) * 16;
      bool f[16];
      transgi::shading::GSample* out[16];
      for (std::size_t i = 0; i < 16; ++i) {
        f[i] = found[first + i] != 0;
        out[i] = &samples[first + i];
      }
      if (tile) {
        transgi::shading::make_gsamples(rt, assets, &rays[first], &hits[first], f, 16, spread, out);
      } else {
        for (std::size_t i = 0; i < 16; ++i)
          transgi::shading::make_gsample(rt, assets, rays[first + i], f[i] ? &hits[first + i] : nullptr, nullptr, spread, *out[i]);
      }
      benchmark::ClobberMemory();
    }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(rays.size()));
}

BENCHMARK(BM_Bf16Peak)->Threads(1)->Threads(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AmxPeak)->Threads(1)->Threads(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FusedShade)->Arg(3)->Arg(2)->Arg(1)->Arg(0)->Threads(1)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FusedShade)->Arg(3)->Arg(2)->Threads(2)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ProbeCage)->Arg(0)->Arg(1)->Arg(0)->Arg(1);
BENCHMARK(BM_GBufferSamples)->Arg(0)->Arg(1)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_OneDnnBf16Chain)->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_InferTransfer)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
// Argument: 32 = f32 sgemm, 16 = bf16 matmul.
BENCHMARK(BM_DecoderForward)->Arg(32)->Arg(16)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DecoderForwardBackward)->Arg(32)->Arg(16)->Unit(benchmark::kMillisecond);
// Arguments: the GEMM (32 or 16, as above) and the gradient blocks (1 = the
// batch's sum in one product; 8 = the default, which makes the bake's bits
// independent of its rank count).
BENCHMARK(BM_TrainerStep)->ArgsProduct({{32, 16}, {1, 8}})->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
