// transgi bench-frame: whole-frame time of the TransGI plugin (probes, GI,
// direct light, composite) while one object of the level orbits and turns
// every frame, so nothing stays cached by accident (issue 10, item 1).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <glm/gtc/quaternion.hpp>

#include "cli/args.h"
#include "cli/option_specs.h"
#include "cli/commands.h"
#include "cli/reference_view.h"
#include "cli/runtime_options.h"
#include "engine/core/cpu_isa.h"
#include "engine/core/progress.h"
#include "engine/image/exr.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"
#include "eval/machine_peak.h"
#include "eval/method_runs.h"
#include "eval/text_output.h"
#include "model/gemm.h"
#include "model/model_file.h"
#include "shading/fused_decoder.h"
#include "shading/upsampling.h"

namespace transgi::cli {

namespace {

using namespace engine;

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::min<double>(static_cast<double>(v.size()) - 1, std::floor(q * static_cast<double>(v.size()))))];
}

// The named mesh node, or the smallest one at least a tenth of the scene's
// size (a piece of furniture, not a wall and not a screw).
ecs::Entity pick_moving_object(ecs::World& world, const std::string& name) {
  const auto& assets = world.resource<scene::SceneAssets>();
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  struct Candidate {
    ecs::Entity e;
    float size;
    std::string name;
  };
  std::vector<Candidate> all;
  world.view<const scene::MeshInstance, const transform::WorldTransform>().each(
      [&](ecs::Entity e, const scene::MeshInstance& m, const transform::WorldTransform& w) {
        const scene::MeshAsset& mesh = *assets.meshes[m.mesh];
        const float size = glm::length(mesh.bounds_max - mesh.bounds_min) * w.scale;
        lo = glm::min(lo, w.apply_point(mesh.bounds_min));
        hi = glm::max(hi, w.apply_point(mesh.bounds_max));
        const scene::Name* nm = world.try_get<scene::Name>(e);
        all.push_back({e, size, nm ? nm->value : std::string()});
      });
  if (!name.empty()) {
    for (const Candidate& c : all)
      if (c.name == name) return c.e;
    throw std::runtime_error("--object: no mesh node named '" + name + "'");
  }
  const float scene_size = glm::length(hi - lo);
  const Candidate* best = nullptr;
  for (const Candidate& c : all)
    if (c.size >= 0.1f * scene_size && (!best || c.size < best->size)) best = &c;
  if (!best) throw std::runtime_error("bench-frame: the scene has no mesh node to move; name one with --object");
  return best->e;
}

}  // namespace

int run_bench_frame(const std::vector<std::string>& argv) {
  const Args args("bench-frame", argv, bench_frame_option_specs(), kBenchFrameSynopsis);
  const std::string scene_path = args.str("scene"), model_path = args.str("model");
  const int width = static_cast<int>(args.integer("width", 16, 8192, 640));
  const int height = static_cast<int>(args.integer("height", 16, 8192, 360));
  const int frames = static_cast<int>(args.integer("frames", 1, 100000, 100));
  const int warmup = static_cast<int>(args.integer("warmup", 0, 100000, 64));
  const std::string preset = args.choice("preset", {"quality", "realtime"}, "realtime");
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  const std::string csv = args.str("csv", std::string());
  // Options first, so a typo is reported before seconds of loading.
  runtime::TransGISettings settings = runtime_settings_from(args, "realtime");

  eval::LoadedScene scene = eval::load_scene(scene_path, args.str("camera", std::string()), threads);
  ecs::World& world = scene.app->world();
  auto model = model::load_model(model_path);
  model::validate_model(model, world.resource<scene::SceneAssets>(), model_path, args.has("allow-unbaked"));
  // The decoder's multiply-adds per point (2 FLOP each), for the inference's
  // rate against the machine's peak; the dot with the light is left out.
  double mlp_flop_per_point = 0;
  for (int l = 0; l < model.decoder.layout().layer_count(); ++l)
    mlp_flop_per_point += 2.0 * model.decoder.layout().in_of(l) * model.decoder.layout().out_of(l);
  settings.direct_spp = static_cast<int>(args.integer("direct-spp", 0, 100000, settings.direct_spp));
  scene.app->add_plugin<runtime::TransGIPlugin>(settings);
  runtime::attach_latent_meshes(world, std::make_shared<const model::TransferModel>(std::move(model)));
  const runtime::ProbePlacement placement = probe_placement_from(args, runtime::ProbeVolumeMode::Cascades);
  runtime::spawn_probes(world, placement);

  const ecs::Entity mover = pick_moving_object(world, args.str("object", std::string()));
  const transform::Transform start = world.get<transform::Transform>(mover);
  const scene::Name* mover_name = world.try_get<scene::Name>(mover);
  const auto& mover_mesh = *world.resource<scene::SceneAssets>().meshes[world.get<scene::MeshInstance>(mover).mesh];
  const float radius = 0.15f * glm::length(mover_mesh.bounds_max - mover_mesh.bounds_min) * start.scale;

  eval::MachinePeak peak;
  scene.app->jobs().run([&] { peak = eval::measure_machine_peak(world.resource<rt::RtScene>()); });
  std::printf("machine, measured now: bf16 %.0f GFLOP/s (vdpbf16ps), amx bf16 %.0f GFLOP/s, fp32 %.0f GFLOP/s, incoherent rays "
              "%.2f Mrays/s (%d threads); fused kernel: %s\n",
              peak.bf16_gflops, peak.amx_gflops, peak.fp32_gflops, peak.incoherent_mrays, scene.app->jobs().thread_count(),
              shading::fused_isa_name(shading::best_fused_isa()));
  std::printf("instruction sets: %s; fused inference %s, upsampling %s, probe kernels %s, GEMM (oneDNN) %s\n",
              engine::cpu::isa_summary().c_str(), shading::fused_isa_name(shading::best_fused_isa()),
              shading::upsampling_isa_name(shading::best_upsampling_isa()),
              engine::cpu::isa_name(std::min(engine::cpu::effective_isa(), engine::cpu::Isa::Avx512)),
              model::onednn_isa_name().c_str());
  std::printf("moving '%s' on a %.3f m orbit, a full turn every 120 frames; preset %s, %dx%d\n",
              mover_name ? mover_name->value.c_str() : "?", static_cast<double>(radius), preset.c_str(), width, height);

  auto& frame = world.resource<runtime::GiFrame>();
  frame.camera = scene.camera;
  frame.width = width;
  frame.height = height;
  std::ostringstream rows;
  rows << "frame,total_ms,gbuffer_ms,inference_ms,sh_light_ms,upsample_ms,probe_trace_ms,probe_raster_ms,probe_project_ms,"
          "direct_ms,antialiasing_ms,reflections_ms,probes_traced,decoded_pixels,gpu_trace_ms,gpu_raster_ms,gpu_projection_ms,gpu_gbuffer_ms,gpu_inference_ms,gpu_shading_ms,gpu_accumulation_ms\n";
  std::vector<double> totals, inference_gflops;
  std::vector<std::vector<double>> stages;
  core::ProgressBar bar("bench-frame", static_cast<std::uint64_t>(warmup + frames), true);
  for (int f = 0; f < warmup + frames; ++f) {
    const float angle = 6.2831853f * static_cast<float>(f) / 120.0f;
    transform::Transform t = start;
    t.translation += radius * glm::vec3(std::cos(angle) - 1.0f, 0.0f, std::sin(angle));
    t.rotation = glm::angleAxis(angle, glm::vec3(0, 1, 0)) * start.rotation;
    world.get_mut<transform::Transform>(mover) = t;  // marks it changed: the plugin follows
    const auto t0 = std::chrono::steady_clock::now();
    scene.app->jobs().run([&] { scene.app->update(); });
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    bar.update(static_cast<std::uint64_t>(f + 1));
    if (f < warmup) continue;
    const auto& s = frame.times;
    const std::vector<double> row{s.gbuffer + s.network_input, s.inference, s.sh_multiplication, s.upsample,
                                  s.collect_points, s.probe_raster, s.probe_projection, s.direct, s.antialiasing, s.reflections};
    totals.push_back(ms);
    stages.push_back(row);
    if (s.inference > 0) inference_gflops.push_back(static_cast<double>(frame.realtime.inferred) * mlp_flop_per_point / (s.inference * 1e6));
    rows << f - warmup << ',' << ms;
    for (double v : row) rows << ',' << v;
    rows << ',' << frame.probe_stats.traced << ',' << frame.shaded_samples << ','
         << frame.device_stage_ms(runtime::device_stage::kOtherRays) << ',' << frame.device_stage_ms(runtime::device_stage::kRaster) << ',' << frame.device_stage_ms(runtime::device_stage::kProjection)
         << ',' << frame.device_stage_ms(runtime::device_stage::kGbufferRays) << ','
         << frame.device_stage_ms(runtime::device_stage::kInference) << ','
         << frame.device_stage_ms(runtime::device_stage::kProbeRays) << ','
         << frame.device_stage_ms(runtime::device_stage::kAccumulation) << '\n';
  }
  bar.finish();
  if (!csv.empty()) eval::write_text(csv, rows.str());

  const char* names[] = {"G-buffer", "inference (fused)", "SH light", "upsampling", "probe rays + shading", "probe raster",
                         "probe accumulation + projection", "direct light", "antialiasing", "reflections"};
  std::printf("frame time over %d frames after %d warm-up: median %.2f ms, p95 %.2f, max %.2f\n", frames, warmup,
              percentile(totals, 0.5), percentile(totals, 0.95), percentile(totals, 1.0));
  std::printf("stage medians (ms):");
  for (std::size_t k = 0; k < std::size(names); ++k) {
    std::vector<double> v;
    for (const auto& r : stages) v.push_back(r[k]);
    std::printf(" %s %.2f;", names[k], percentile(v, 0.5));
  }
  std::printf("\n");
  std::printf("last frame: %zu pixels lit (%zu grid, %zu edge; %zu of them with a kept transfer, not decoded), %zu grid cells reused from the frame before, %zu rotations, %zu reflection rays, %d probes traced\n",
              frame.realtime.grid_samples + frame.realtime.edge_samples, frame.realtime.grid_samples,
              frame.realtime.edge_samples, frame.realtime.kept_transfers, frame.realtime.reused_cells, frame.realtime.rotations, frame.realtime.reflection_rays,
              frame.probe_stats.traced);
  if (!inference_gflops.empty()) {
    const shading::FusedIsa isa = shading::best_fused_isa();
    const double peak_gflops = isa == shading::FusedIsa::Amx          ? peak.amx_gflops
                               : isa == shading::FusedIsa::Avx512Bf16 ? peak.bf16_gflops
                               : isa == shading::FusedIsa::Avx2       ? peak.fp32_gflops
                                                                      : 0.0;
    const double rate = percentile(inference_gflops, 0.5);
    std::printf("inference rate: %zu points last frame x %.1f kFLOP (the decoder's multiply-adds); median %.1f GFLOP/s", frame.realtime.inferred,
                mlp_flop_per_point * 1e-3, rate);
    if (peak_gflops > 0)
      std::printf(", %.0f %% of the %s peak measured above (%.0f GFLOP/s)", 100.0 * rate / peak_gflops,
                  isa == shading::FusedIsa::Avx2 ? "fp32 FMA" : isa == shading::FusedIsa::Amx ? "AMX bf16" : "AVX-512 bf16",
                  peak_gflops);
    std::printf("\n");
  }
  world.view<const runtime::ProbeCascades>().each([&](const runtime::ProbeCascades& set) {
    if (set.state.fitted_to_scene)
      std::printf("cascades: the scene is small enough for one grid over its %s (--cascade-fit-scene)\n",
                  set.state.far_field ? "geometry less its ground plane, with the far field beyond" : "bounds");
    for (std::size_t k = 0; k < set.state.fields.size() && k < frame.cascade_stats.size(); ++k) {
      const probes::ProbeFrameStats& c = frame.cascade_stats[k];
      const glm::vec3 cell = set.state.fields[k]->grid().spacing();
      std::printf("cascade %zu (%.2f x %.2f x %.2f m cells): %d traced, %d active, %d converged, %d buried, %d far\n", k,
                  static_cast<double>(cell.x), static_cast<double>(cell.y), static_cast<double>(cell.z), c.traced, c.active,
                  c.converged, c.buried, c.far);
    }
  });
  if (!csv.empty()) std::printf("per-frame CSV: %s\n", csv.c_str());
  std::printf("probe kernels: %s%s%s", frame.backend.c_str(), frame.backend_fallback.empty() ? "" : "; ",
              frame.backend_fallback.c_str());
  std::printf("\n");
  if (frame.gpu_ms() > 0) {
    std::printf("GPU timestamps, last frame (ms):");
    for (const runtime::DeviceStageTime& stage : frame.device_stages) std::printf(" %s %.2f;", stage.name.c_str(), stage.ms);
    std::printf(" total %.2f\n", frame.gpu_ms());
  }
  if (frame.backend != "cpu")
    std::printf("host-device traffic, last frame: %llu submissions, %.2f MB to the device, %.2f MB back (the final image: "
                "%.2f MB)\n",
                static_cast<unsigned long long>(frame.gpu_submissions), static_cast<double>(frame.gpu_upload_bytes) * 1e-6,
                static_cast<double>(frame.gpu_download_bytes) * 1e-6,
                static_cast<double>(frame.full.pixels.size() * sizeof(glm::vec3)) * 1e-6);
  std::printf("direct light, last frame: %zu shadow rays to %zu punctual lights\n", frame.direct_stats.shadow_rays,
              frame.direct_stats.lights);
  // The NaN guards (docs/reliability.md): what each stage's boundary replaced in the last frame.
  std::printf("non-finite values replaced, last frame: %zu decoded samples, %zu direct pixels, %zu probe rays, %d probes restarted\n",
              frame.realtime.nonfinite_samples, frame.direct_stats.nonfinite_pixels, frame.probe_stats.nonfinite_rays,
              frame.probe_stats.nonfinite_probes);

  // Accuracy with the object moving: the last frame's GI, and the path
  // tracer's GI pass of the scene exactly as it stands after that frame.
  if (args.has("gi-out")) {
    image::write_exr(args.str("gi-out"), frame.gi);
    std::printf("GI of the last frame: %s\n", args.str("gi-out").c_str());
  }
  if (args.has("reference-out")) {
    const int spp = static_cast<int>(args.integer("reference-spp", 1, 1 << 20, 1024));
    core::ProgressBar ref_bar("reference", static_cast<std::uint64_t>(spp), true);
    const image::ImageRGB ref =
        reference_gi_now(scene, width, height, spp, [&](int done, int) { ref_bar.update(static_cast<std::uint64_t>(done)); });
    ref_bar.finish();
    image::write_exr(args.str("reference-out"), ref);
    std::printf("reference GI pass of the moved scene (%d spp): %s\n", spp, args.str("reference-out").c_str());
  }
  return 0;
}

}  // namespace transgi::cli
