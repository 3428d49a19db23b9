// A whole GI frame through the plugin with the probe kernels on the CPU and
// on Vulkan (--backend vulkan): the Cornell box after 16 frames.
#include <gtest/gtest.h>

#include <tuple>

#include <cmath>
#include <cstdlib>
#include <cstdio>

#include "bake/trainer.h"
#include "engine/image/metrics.h"
#include "engine/math/rng.h"
#include "engine/scene/scene_assets.h"
#include "eval/method_runs.h"
#include "gpu/vulkan_ddgi_kernels.h"
#include "gpu_fixture.h"

using namespace transgi;

namespace {

eval::MethodRun cornell(runtime::Backend backend) {
  eval::TransgiRunOptions t;
  t.frames = 16;
  t.progress = false;
  t.settings.backend = backend;
  t.settings.direct_spp = 0;
  t.settings.probes.map = probes::MapLayout{32, 16};
  t.settings.probes.fixed_pattern = true;  // the same rays on both runs
  t.placement.mode = runtime::ProbeVolumeMode::Scene;
  t.placement.scene_dims = glm::ivec3(6);
  eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf", "", 2);
  return eval::run_transgi(scene, std::make_shared<const model::TransferModel>(), 48, 48, t);
}

// The real-time path with a network (random latents and weights: the test is
// of equality, not of light), so the frame's transfer inference runs on the
// device when the backend is Vulkan.
eval::MethodRun cornell_realtime(runtime::Backend backend, int width, bool device_inference = true, bool device_lights = true) {
  eval::TransgiRunOptions t;
  t.frames = 12;
  t.progress = false;
  t.settings.gi_path = runtime::GiPath::Realtime;
  t.settings.backend = backend;
  t.settings.device_inference = device_inference;
  t.settings.realtime.device_lights = device_lights;
  t.settings.direct_spp = 0;
  t.settings.probes.map = probes::MapLayout{32, 16};
  t.settings.probes.fixed_pattern = true;
  t.placement.mode = runtime::ProbeVolumeMode::Scene;
  t.placement.scene_dims = glm::ivec3(6);
  eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf", "", 2);
  const auto& assets = scene.app->world().resource<engine::scene::SceneAssets>();
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = width, .hidden_layers = 3}, 11);
  engine::math::Pcg32 rng(8, 9);
  for (auto& mesh : m.meshes)
    for (float& v : mesh.latents.values) v = 2.0f * rng.next_float() - 1.0f;
  return eval::run_transgi(scene, std::make_shared<const model::TransferModel>(std::move(m)), 48, 48, t);
}

// The mean |GI| over pixels and channels (a random network's GI can be negative).
double mean_abs(const engine::image::ImageRGB& img) {
  double mean = 0;
  for (const auto& p : img.pixels) mean += std::abs(p.r + p.g + p.b) / 3.0;
  return mean / static_cast<double>(img.pixels.size());
}

}  // namespace

// The real-time frame on the Vulkan backend with its transfer decoded by the
// device against the same frame decoded by the CPU's scalar fp32 kernel
// (TRANSGI_FUSED_ISA=scalar; the default bf16 kernels round weights to 1e-2):
// the same G-buffer and probes, so only the decoding differs, in summation
// order. Within 1e-4 of the mean |GI|. (Against the CPU backend a random
// network would not do: a pixel centre on an edge that the two tracers give
// to different triangles takes a random latent.)
TEST(VulkanBackend, ARealtimeFrameDecodedOnTheDeviceEqualsTheCpuDecoding) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  struct ScalarIsa {
    ScalarIsa() { setenv("TRANSGI_FUSED_ISA", "scalar", 1); }
    ~ScalarIsa() { unsetenv("TRANSGI_FUSED_ISA"); }
  } scalar;
  const eval::MethodRun cpu = cornell_realtime(runtime::Backend::Vulkan, 32, false);
  const eval::MethodRun gpu = cornell_realtime(runtime::Backend::Vulkan, 32, true);
  ASSERT_EQ(gpu.backend.rfind("vulkan", 0), 0u) << "the plugin fell back: " << gpu.backend;
  EXPECT_EQ(gpu.backend.find("transfer inference on the CPU"), std::string::npos) << gpu.backend;
  ASSERT_GT(gpu.inferred_samples, 0u) << "the network decoded nothing";
  const double mean = mean_abs(cpu.gi);
  ASSERT_GT(mean, 1e-4) << "a black frame would prove nothing";
  const double rmse = engine::image::rmse_clamped(cpu.gi, gpu.gi);
  std::printf("Cornell box, real-time, 12 frames, 48x48, %zu samples decoded: GI RMSE between device and CPU decoding %.3g, "
              "mean |GI| %.4f\n", gpu.inferred_samples, rmse, mean);
  EXPECT_LT(rmse, 1e-4 * mean) << "expected the decodings within 1e-4 of the mean |GI|, got RMSE " << rmse;
}

// Issue 36 counts a frame's submissions (its goal: one). The box's frame
// rides on two: the probes' (the camera's visibility pass and the ceiling
// light's probe samples' shadow rays queued before their rays, as a moved
// object's TLAS rebuild would be; then the rays, their own depth, raster,
// accumulation and projection), and the inference with its probe lights.
// A third would be a stage submitting on its own again.
TEST(VulkanBackend, ARealtimeFrameSubmitsAtMostTwoCommandBuffers) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const eval::MethodRun gpu = cornell_realtime(runtime::Backend::Vulkan, 32, true);
  ASSERT_EQ(gpu.backend.rfind("vulkan", 0), 0u) << "the plugin fell back: " << gpu.backend;
  std::printf("Cornell box, real-time, the 12th frame: %llu submissions\n", static_cast<unsigned long long>(gpu.gpu_submissions));
  EXPECT_GT(gpu.gpu_submissions, 0u);
  EXPECT_LE(gpu.gpu_submissions, 2u);
}

// The sample level's real-time frame (the real-time preset: its sun shaded
// with one shadow ray a pixel, the transfer decoded on the CPU) on Vulkan
// rides on one submission (issue 36): the camera's view, its shadow rays
// (traced with the view: render/view_shadows.h), the probes' emitter
// samples and rays, their depth, raster, accumulation and projection. The
// network is untrained (the test counts submissions, not light). A second
// submission would be a stage submitting on its own again.
TEST(VulkanBackend, TheSampleLevelsRealtimeFrameSubmitsOneCommandBuffer) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  eval::TransgiRunOptions t;
  t.frames = 6;
  t.progress = false;
  t.settings = runtime::realtime_preset();
  t.settings.backend = runtime::Backend::Vulkan;
  t.settings.probes.map = probes::MapLayout{32, 16};
  t.placement.mode = runtime::ProbeVolumeMode::Scene;
  t.placement.scene_dims = glm::ivec3(4);
  eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  const auto& assets = scene.app->world().resource<engine::scene::SceneAssets>();
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 32, .hidden_layers = 3}, 11);
  const eval::MethodRun gpu = eval::run_transgi(scene, std::make_shared<const model::TransferModel>(std::move(m)), 48, 27, t);
  ASSERT_EQ(gpu.backend.rfind("vulkan", 0), 0u) << "the plugin fell back: " << gpu.backend;
  std::printf("sample level, real-time, the 6th frame: %llu submissions\n", static_cast<unsigned long long>(gpu.gpu_submissions));
  EXPECT_EQ(gpu.gpu_submissions, 1u);
}

// The device decodes both frames; in one it also makes the lights from the
// probes (probe_lights.comp), in the other the CPU writes them: the same
// interpolation, so within 1e-4 of the mean |GI| again.
TEST(VulkanBackend, ARealtimeFrameWithLightsMadeOnTheDeviceEqualsOneWithTheCpusLights) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const eval::MethodRun cpu_lights = cornell_realtime(runtime::Backend::Vulkan, 32, true, false);
  const eval::MethodRun gpu_lights = cornell_realtime(runtime::Backend::Vulkan, 32, true, true);
  ASSERT_EQ(gpu_lights.backend.rfind("vulkan", 0), 0u) << "the plugin fell back: " << gpu_lights.backend;
  ASSERT_GT(gpu_lights.inferred_samples, 0u) << "the network decoded nothing";
  const double mean = mean_abs(cpu_lights.gi);
  ASSERT_GT(mean, 1e-4) << "a black frame would prove nothing";
  const double rmse = engine::image::rmse_clamped(cpu_lights.gi, gpu_lights.gi);
  std::printf("Cornell box, real-time, 12 frames, 48x48: GI RMSE between lights made on the device and by the CPU %.3g, "
              "mean |GI| %.4f\n", rmse, mean);
  EXPECT_LT(rmse, 1e-4 * mean) << "expected the two within 1e-4 of the mean |GI|, got RMSE " << rmse;
}

// A network wider than the kernels hold (256): the frame still renders, the
// CPU decodes, and the backend says so.
TEST(VulkanBackend, ANetworkTooWideForTheKernelIsDecodedOnTheCpuAndSaysSo) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const eval::MethodRun gpu = cornell_realtime(runtime::Backend::Vulkan, 256);
  ASSERT_EQ(gpu.backend.rfind("vulkan", 0), 0u) << gpu.backend;
  EXPECT_NE(gpu.backend.find("transfer inference on the CPU"), std::string::npos) << gpu.backend;
  EXPECT_GT(gpu.inferred_samples, 0u);
}

// The probe rays are traced through the GPU BVH (hit distances round
// differently from Embree's), the raster is the CPU's arithmetic in the CPU's
// order and the projection differs only in summation order (fp32 partial
// sums against double): after 16 frames of feedback through the probes the
// images stay within 1e-4 of the mean GI (measured 3.7e-7, 1.2 % of that).
TEST(VulkanBackend, ACornellBoxGiFrameEqualsTheCpuBackends) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const eval::MethodRun cpu = cornell(runtime::Backend::Cpu);
  const eval::MethodRun gpu = cornell(runtime::Backend::Vulkan);
  ASSERT_EQ(gpu.backend.rfind("vulkan", 0), 0u) << "the plugin fell back: " << gpu.backend;
  EXPECT_EQ(gpu.backend.find("the CPU backend runs"), std::string::npos) << gpu.backend;
  const double mean = gpu_test::mean_rgb(cpu.gi);
  ASSERT_GT(mean, 1e-3) << "the Cornell box's GI should not be black";
  const double rmse = engine::image::rmse_clamped(cpu.gi, gpu.gi);
  std::printf("Cornell box, 16 frames, 48x48: GI RMSE between backends %.3g, mean GI %.4f (%s)\n", rmse, mean, gpu.backend.c_str());
  EXPECT_LT(rmse, 1e-4 * mean) << "expected the backends within 1e-4 of the mean GI, got RMSE " << rmse;
}

namespace {

// DDGI's GI after 16 updates on one backend, its probes placed as asked.
// `realtime`: the game's shape (ddgi::DdgiRenderOptions::realtime, a probe
// budget, emitted maps if asked) instead of eval's.
// `raster`: on the Vulkan backend, the camera's view rasterised (the
// default, GpuOptions::raster_visibility) or its rays traced.
// DDGI's Vulkan backend on a device of its own; `raster`: the camera's view
// rasterised (GpuOptions::raster_visibility) or its rays traced.
ddgi::DdgiBackend vulkan_ddgi_backend(bool raster = true) {
  engine::gpu::GpuOptions options;
  options.raster_visibility = raster;
  std::string why;
  std::shared_ptr<engine::gpu::VulkanContext> device = engine::gpu::VulkanContext::create(options, &why);
  EXPECT_TRUE(device) << why;
  return gpu::make_ddgi_backend("vulkan", "", std::move(device));
}

eval::MethodRun cornell_ddgi(bool gpu, const runtime::ProbePlacement& placement, bool realtime = false, int width = 48,
                             bool emitted_maps = false, bool raster = true) {
  eval::DdgiRunOptions d;
  d.render.realtime = realtime;
  d.settings.emitted_maps = emitted_maps;
  d.settings.probes_per_update = realtime ? 64 : 0;
  d.frames = 16;
  d.progress = false;
  d.render.direct_spp = 0;
  d.settings.rays_per_probe = 64;
  d.settings.warmup_frames = 8;
  d.placement = placement;
  if (gpu) d.backend = vulkan_ddgi_backend(raster);
  EXPECT_EQ(d.backend.fallback, probes::BackendFallback::None) << d.backend.fallback_why;
  eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf", "", 2);
  return eval::run_ddgi(scene, width, 48, d);
}

}  // namespace

// DDGI on both backends (its probe rays traced through the GPU BVH, the blend
// and the image's lookups as kernels): the Cornell box's GI after 16 updates.
TEST(VulkanBackend, ACornellBoxDdgiFrameEqualsTheCpuBackends) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  runtime::ProbePlacement placement;
  placement.mode = runtime::ProbeVolumeMode::Scene;
  placement.scene_dims = glm::ivec3(6);
  const eval::MethodRun cpu = cornell_ddgi(false, placement), gpu = cornell_ddgi(true, placement);
  const double mean = gpu_test::mean_rgb(cpu.gi);
  ASSERT_GT(mean, 1e-3);
  const double rmse = engine::image::rmse_clamped(cpu.gi, gpu.gi);
  std::printf("Cornell box DDGI, 16 updates, 48x48: GI RMSE between backends %.3g, mean GI %.4f\n", rmse, mean);
  EXPECT_LT(rmse, 1e-4 * mean) << "expected the backends within 1e-4 of the mean GI, got RMSE " << rmse;
}

// The game's real-time DDGI frame (one G-buffer sample a pixel,
// deterministic direct light, a probe budget after the warm-up) on both
// backends: the probes' rays traced on the device, the blend as a kernel,
// the lookups as a kernel (with emitted maps, theirs too, through each
// volume's emitted view). The full image and both passes. 51 pixels wide: at
// an even width the box's corner edges run through pixel centres, where the
// compute traversal and Embree pick different ones of two tied walls.
// With the camera's rays traced on the device, every stage after them must
// give the CPU's frame to 1e-4 of the mean (RMSE). With the camera's view
// rasterised (the default), the box's block edges fall exactly on a column
// of jittered samples, which the rasteriser's top-left rule gives to the
// wall behind and the ray to the block, and the antialiasing's history
// carries the difference to its neighbours: at most 3 % of the pixels may
// then differ by more than 1e-3 of the mean (measured 42 of 2,448), and over
// the rest the 1e-4 holds (measured 1.4e-6 at most, against means of
// 0.02-0.11).
TEST(VulkanBackend, ACornellBoxRealtimeDdgiFrameEqualsTheCpuBackends) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  runtime::ProbePlacement placement;
  placement.mode = runtime::ProbeVolumeMode::Scene;
  placement.scene_dims = glm::ivec3(6);
  for (bool emitted : {false, true}) {
    const eval::MethodRun cpu = cornell_ddgi(false, placement, true, 51, emitted);
    for (const bool raster : {false, true}) {
      const eval::MethodRun gpu = cornell_ddgi(true, placement, true, 51, emitted, raster);
      for (const auto& [name, a, b] : {std::tuple{"full", &cpu.full, &gpu.full}, std::tuple{"direct", &cpu.direct, &gpu.direct},
                                       std::tuple{"gi", &cpu.gi, &gpu.gi}}) {
        const double mean = gpu_test::mean_rgb(*a);
        ASSERT_GT(mean, 1e-3) << name;
        std::size_t apart = 0;
        double rest = 0;
        for (std::size_t i = 0; i < a->pixels.size(); ++i) {
          const glm::vec3 d = glm::min(glm::abs(a->pixels[i] - b->pixels[i]), glm::vec3(1.0f));
          if (glm::max(d.r, glm::max(d.g, d.b)) > 1e-3 * mean) ++apart;
          else rest += (d.r * d.r + d.g * d.g + d.b * d.b) / 3.0;
        }
        const double rmse = engine::image::rmse_clamped(*a, *b);
        const double rest_rmse = std::sqrt(rest / static_cast<double>(a->pixels.size() - apart));
        std::printf("Cornell box real-time DDGI, emitted maps %s, camera %s, 16 updates, 51x48, %s: RMSE between backends "
                    "%.3g (%zu pixels apart, the rest %.3g), mean %.4f\n",
                    emitted ? "on" : "off", raster ? "rasterised" : "rays", name, rmse, apart, rest_rmse, mean);
        const std::string what = std::string(name) + (emitted ? ", emitted maps" : "") + (raster ? ", rasterised" : ", rays");
        if (!raster) {
          EXPECT_LT(rmse, 1e-4 * mean) << what;
        } else {
          EXPECT_LE(apart, 3 * a->pixels.size() / 100) << what;
          EXPECT_LT(rest_rmse, 1e-4 * mean) << what;
        }
      }
    }
  }
}

// DDGI's real-time frame on the sample level, whose sun is a punctual light:
// on Vulkan its shadow rays are traced with the queued camera view (no
// Embree, no submission of their own), and the direct pass equals the CPU
// backend's (Embree's packets over the CPU's G-buffer) to 1e-4 RMSE; at most
// three submissions, as on the Cornell box.
TEST(VulkanBackend, TheSampleLevelsRealtimeDdgiDirectLightIsTracedWithTheView) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const auto run = [](bool gpu) {
    eval::DdgiRunOptions d;
    d.render.realtime = true;
    d.settings.probes_per_update = 64;
    d.frames = 6;
    d.progress = false;
    d.render.direct_spp = 0;
    d.settings.rays_per_probe = 32;
    d.settings.warmup_frames = 4;
    d.placement.mode = runtime::ProbeVolumeMode::Scene;
    d.placement.scene_dims = glm::ivec3(4);
    if (gpu) d.backend = vulkan_ddgi_backend();
    eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
    return eval::run_ddgi(scene, 64, 36, d);
  };
  const eval::MethodRun gpu = run(true), cpu = run(false);
  ASSERT_EQ(gpu.backend.rfind("vulkan", 0), 0u) << gpu.backend;
  double mean = 0;
  for (const auto& p : cpu.direct.pixels) mean += p.g;
  mean /= static_cast<double>(cpu.direct.pixels.size());
  ASSERT_GT(mean, 1e-3) << "no sun in the direct pass";
  const double rmse = engine::image::rmse_clamped(gpu.direct, cpu.direct);
  std::printf("sample level, real-time DDGI, the 6th frame: %llu submissions, direct RMSE against the CPU backend %.3g (mean %.4f)\n",
              static_cast<unsigned long long>(gpu.gpu_submissions), rmse, mean);
  EXPECT_LT(rmse, 1e-4);
  EXPECT_GT(gpu.gpu_submissions, 0u);
  EXPECT_LE(gpu.gpu_submissions, 3u);
}

// DDGI's real-time frame on Vulkan counts its submissions too (issue 36):
// the probe rays (the camera's view queued at their head), the blend and
// the probes' irradiance at the pixels (one per volume set: the emitted
// maps' lookup is one more). A fourth would be the camera's view drawn on
// its own again.
TEST(VulkanBackend, ARealtimeDdgiFrameSubmitsAtMostThreeCommandBuffers) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  runtime::ProbePlacement placement;
  placement.mode = runtime::ProbeVolumeMode::Scene;
  placement.scene_dims = glm::ivec3(6);
  const eval::MethodRun gpu = cornell_ddgi(true, placement, true, 51);
  ASSERT_EQ(gpu.backend.rfind("vulkan", 0), 0u) << gpu.backend;
  std::printf("Cornell box, real-time DDGI, the 16th frame: %llu submissions\n", static_cast<unsigned long long>(gpu.gpu_submissions));
  EXPECT_GT(gpu.gpu_submissions, 0u);
  EXPECT_LE(gpu.gpu_submissions, 3u);
}

// Several volumes (camera-centred cascades, handing points over across their
// blend bands and to the next where none of a volume's probes weighs in):
// the device looks every point up in each volume, the CPU blends them as
// irradiance_from does. Same bound. The finest cell is not a fraction of the
// box's 2 m: 0.25 m put probes on the walls' planes, whose classification
// rays then met the box's edges and corners exactly, where Embree, the
// compute traversal and ray queries each pick another of the tied triangles
// (all at the same t), and one probe's classification flipped with the tie.
TEST(VulkanBackend, ACornellBoxDdgiFrameWithCascadesEqualsTheCpuBackends) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  runtime::ProbePlacement placement;
  placement.mode = runtime::ProbeVolumeMode::Cascades;
  placement.cascades.count = 3;
  placement.cascades.finest_cell = 0.23f;
  placement.cascades.look_ahead = 0.75f;  // the camera stands outside the box: reach into it
  placement.cascades.fit_scene_cell = 0.0f;  // cascades however small the scene
  const eval::MethodRun cpu = cornell_ddgi(false, placement), gpu = cornell_ddgi(true, placement);
  const double mean = gpu_test::mean_rgb(cpu.gi);
  ASSERT_GT(mean, 1e-3);
  const double rmse = engine::image::rmse_clamped(cpu.gi, gpu.gi);
  std::printf("Cornell box DDGI, 3 cascades, 16 updates, 48x48: GI RMSE between backends %.3g, mean GI %.4f (%s)\n", rmse,
              mean, gpu.probe_summary.c_str());
  EXPECT_LT(rmse, 1e-4 * mean) << "expected the backends within 1e-4 of the mean GI, got RMSE " << rmse;
}

// A device whose largest buffer cannot hold the sample level's triangles:
// DDGI's first device stage throws, and the plugin runs that frame and every
// later one on the CPU backend whole, saying why. The frame is the CPU
// backend's, bit for bit.
TEST(VulkanBackend, ADdgiSceneTooBigForTheDeviceRunsTheWholeFrameOnTheCpuBackend) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  engine::gpu::GpuOptions options;
  options.storage_buffer_range_cap = 64 * 1024;  // the level's triangles take more
  std::string why;
  std::shared_ptr<engine::gpu::VulkanContext> ctx(engine::gpu::VulkanContext::create(options, &why));
  ASSERT_TRUE(ctx) << why;
  const auto run = [&](std::shared_ptr<ddgi::DdgiKernels> kernels) {
    eval::DdgiRunOptions d;
    d.frames = 12;
    d.settings.warmup_frames = 8;
    d.progress = false;
    d.render.direct_spp = 0;
    d.settings.rays_per_probe = 32;
    d.placement.mode = runtime::ProbeVolumeMode::Scene;
    d.placement.scene_dims = glm::ivec3(4);
    if (kernels) d.backend.kernels = std::move(kernels);
    eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
    return eval::run_ddgi(scene, 32, 18, d);
  };
  const eval::MethodRun capped = run(std::make_shared<gpu::VulkanDdgiKernels>(ctx)), cpu = run(nullptr);
  gpu_test::expect_cpu_fallback_frame(capped.backend, capped.gi, cpu.backend, cpu.gi);
}
