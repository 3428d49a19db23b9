#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "cli/args.h"
#include "cli/commands.h"
#include "cli/option_specs.h"
#include "cli/runtime_options.h"
#include "gpu/vulkan_ddgi_kernels.h"
#include "cli/sun_options.h"
#include "engine/core/progress.h"
#include "engine/image/exr.h"
#include "engine/image/tonemap.h"
#include "engine/render/path_tracer.h"
#include "engine/scene/scene_assets.h"
#include "eval/method_runs.h"
#include "model/model_file.h"
#include "shading/transfer_renderer.h"

namespace transgi::cli {

namespace {

using namespace engine;

// --pass all writes OUT (full), OUT_direct.exr and OUT_gi.exr from the same samples.
std::string sibling(const std::string& path, const std::string& suffix) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

std::vector<std::string> split_names(const std::string& list) {
  std::vector<std::string> names;
  std::size_t b = 0;
  while (b <= list.size()) {
    const std::size_t e = std::min(list.find(',', b), list.size());
    if (e > b) names.push_back(list.substr(b, e - b));
    b = e + 1;
  }
  return names;
}

struct Outputs {
  std::string out, png;
  double exposure = 0;
  std::string pass;
};

// The path tracer's surface passes (the real-time methods have none): the
// albedo (--pass albedo, and with --pass all) and where the surfaces are
// textured or coloured (with --pass all: compare --colour-mask takes it).
struct SurfacePasses {
  image::ImageRGB albedo, textured;
};

void write_passes(const Outputs& o, const image::ImageRGB& full, const image::ImageRGB& direct, const image::ImageRGB& gi,
                  const SurfacePasses* surfaces = nullptr) {
  const image::ImageRGB& main = o.pass == "gi" ? gi : o.pass == "direct" ? direct : o.pass == "albedo" ? surfaces->albedo : full;
  image::write_exr(o.out, main);
  if (o.pass == "all") {
    image::write_exr(sibling(o.out, "_direct"), direct);
    image::write_exr(sibling(o.out, "_gi"), gi);
    if (surfaces) {
      image::write_exr(sibling(o.out, "_albedo"), surfaces->albedo);
      image::write_exr(sibling(o.out, "_textured"), surfaces->textured);
    }
  }
  if (o.png.empty()) return;
  image::write_png_srgb(o.png, main, static_cast<float>(o.exposure));
  if (o.pass == "all") {
    image::write_png_srgb(sibling(o.png, "_direct"), direct, static_cast<float>(o.exposure));
    image::write_png_srgb(sibling(o.png, "_gi"), gi, static_cast<float>(o.exposure));
    if (surfaces) {
      image::write_png_srgb(sibling(o.png, "_albedo"), surfaces->albedo, static_cast<float>(o.exposure));
      image::write_png_srgb(sibling(o.png, "_textured"), surfaces->textured, static_cast<float>(o.exposure));
    }
  }
}

void print_stages(const eval::MethodRun& r, int timed) {
  std::printf("  %s\n  stage times, median of the last %d frames (ms):", r.probe_summary.c_str(), timed);
  for (const auto& s : r.stages) std::printf(" %s %.2f;", s.name.c_str(), s.ms);
  std::printf(" total without direct light %.2f\n", r.frame_ms);
}

// The object-scale setting (paper Fig. 7): the environment projected to SH is
// the only light; the background shows the environment.
int render_object_scale(const Args& args, eval::LoadedScene& scene, transgi::model::TransferModel model, int width, int height,
                        const Outputs& o) {
  ecs::World& world = scene.app->world();
  const auto& assets = world.resource<scene::SceneAssets>();
  const auto& rt_scene = world.resource<rt::RtScene>();
  const std::string transfer = args.choice("transfer", {"network", "ground-truth"}, "network");
  transgi::shading::TransferRenderSettings rs;
  rs.spp = static_cast<int>(args.integer("spp", 1, 1'000'000, 4));
  rs.ground_truth_rays = static_cast<int>(args.integer("gt-rays", 1, 1'000'000, 2048));
  rs.seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  const engine::render::CameraRays camera(world.get<scene::Camera>(scene.camera), world.get<transform::WorldTransform>(scene.camera),
                                          width, height);
  const auto source = transfer == "network" ? transgi::shading::TransferSource::Network : transgi::shading::TransferSource::GroundTruth;
  const auto light = transgi::shading::project_environment(*assets.environment);
  transgi::shading::TransferRenderResult r;
  scene.app->jobs().run([&] {
    r = transgi::shading::render_transfer(rt_scene, assets, model, camera, width, height, transgi::shading::constant_light(light),
                                          &*assets.environment, source, rs);
  });
  write_passes(o, r.image, r.image, r.image);
  if (args.has("coefficient-maps")) {
    const std::string prefix = args.str("coefficient-maps");
    const char* names[3] = {"_sh00.exr", "_sh10.exr", "_sh20.exr"};
    for (int i = 0; i < 3; ++i) image::write_exr(prefix + names[i], r.coefficient_maps[static_cast<std::size_t>(i)]);
  }
  std::printf("rendered %s (transgi, %s transfer, environment SH light) %dx%d at %d spp: %zu shaded samples\n", o.out.c_str(),
              transfer.c_str(), width, height, rs.spp, r.shaded_samples);
  std::printf("  stage times (ms): G-buffer %.2f, generate network input %.2f, network inference %.2f, SH multiplication %.2f\n",
              r.timings.gbuffer_ms, r.timings.inputs_ms, r.timings.inference_ms, r.light_ms + r.timings.shading_ms);
  return 0;
}

// TransGI at scene scale, through the engine plugin: SH light probes updated
// for --frames frames; --pass full adds direct light (--direct-spp samples).
int render_transgi(const Args& args, eval::LoadedScene& scene, int width, int height, const Outputs& o) {
  const std::string model_path = args.str("model");
  const std::string lighting = args.choice("lighting", {"probes", "environment"}, "probes");
  // The scene's basic requirement first: a stale model would hide it.
  if (lighting == "environment" && !scene.app->world().resource<scene::SceneAssets>().environment)
    throw std::runtime_error("--lighting environment needs an environment light in the scene (scenes[0].extras.environment)");
  auto model = transgi::model::load_model(model_path);
  const std::string transfer = args.choice("transfer", {"network", "ground-truth"}, "network");
  if (transfer == "network")
    transgi::model::validate_model(model, scene.app->world().resource<scene::SceneAssets>(), model_path, args.has("allow-unbaked"));
  if (lighting == "environment") return render_object_scale(args, scene, std::move(model), width, height, o);
  if (transfer != "network") throw std::runtime_error("--transfer ground-truth needs --lighting environment");
  if (args.has("coefficient-maps")) throw std::runtime_error("--coefficient-maps needs --lighting environment");

  eval::TransgiRunOptions t;
  t.settings = runtime_settings_from(args, "quality");
  t.settings.gbuffer_spp = static_cast<int>(args.integer("spp", 1, 1'000'000, 1));
  t.settings.seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  t.settings.direct_spp = o.pass == "gi" ? 0 : static_cast<int>(args.integer("direct-spp", 1, 100000, 16));
  t.settings.probes.rays_per_probe = static_cast<int>(args.integer("probe-rays", 1, 100000, 100));
  t.settings.probes.seed = t.settings.seed + 1;
  const bool skip = args.choice("probe-skip", {"on", "off"}, "on") == "on";
  t.settings.probes.skip.classify = t.settings.probes.skip.skip_converged = skip;
  t.settings.probes.sharing.mode = args.choice("sharing", {"depth-guard", "paper"}, "depth-guard") == "paper"
                                       ? transgi::probes::SharingMode::PaperFaithful
                                       : transgi::probes::SharingMode::DepthGuard;
  t.settings.temporal_window = static_cast<int>(args.integer("temporal-window", 1, 1024, t.settings.temporal_window));
  // By default the still image's window starts once the probes' cold start
  // is over: a mean over warm-up frames is an image of the warm-up (on a
  // daylit room, 32 frames averaged frames 17-32 and came out 8-10 % bright).
  t.frames = static_cast<int>(
      args.integer("frames", 1, 100000, t.settings.probes.accumulation.warmup_frames + t.settings.temporal_window));
  t.timing_frames = static_cast<int>(args.integer("timing-frames", 1, 1000, 3));
  t.placement = probe_placement_from(args, runtime::ProbeVolumeMode::Cascades);
  t.no_latent = split_names(args.str("no-latent", std::string()));
  const auto shared = std::make_shared<const transgi::model::TransferModel>(std::move(model));
  const eval::MethodRun r = eval::run_transgi(scene, shared, width, height, t);
  write_passes(o, r.full, r.direct, r.gi);
  std::printf("rendered %s (transgi, probe light, %s pass) %dx%d at %d spp: %zu shaded samples, %zu inferred\n", o.out.c_str(),
              o.pass.c_str(), width, height, t.settings.gbuffer_spp, r.shaded_samples, r.inferred_samples);
  std::printf("probe kernels: %s\n", r.backend.c_str());
  print_stages(r, std::min(t.timing_frames, t.frames));
  return 0;
}

int render_ddgi(const Args& args, eval::LoadedScene& scene, int width, int height, const Outputs& o) {
  eval::DdgiRunOptions d;
  d.render.gbuffer_spp = static_cast<int>(args.integer("spp", 1, 1'000'000, 1));
  d.render.seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  d.render.direct_spp = o.pass == "gi" ? 0 : static_cast<int>(args.integer("direct-spp", 1, 100000, 16));
  d.settings.rays_per_probe = static_cast<int>(args.integer("probe-rays", 1, 100000, 256));
  d.settings.seed = d.render.seed + 1;
  d.settings.hysteresis = static_cast<float>(args.number("hysteresis", 0.0, 1.0, d.settings.hysteresis));
  d.settings.brightness_threshold = static_cast<float>(args.number("brightness-threshold", 0.0, 1e30, d.settings.brightness_threshold));
  // eval's cold start: RTXGI's (0) leaves a room nearly black for hundreds of updates.
  d.settings.warmup_frames = static_cast<int>(args.integer("warmup-frames", 0, 100000, 64));
  d.settings.irradiance_gamma = static_cast<float>(args.number("irradiance-gamma", 0.1, 20.0, d.settings.irradiance_gamma));
  d.frames = static_cast<int>(args.integer("frames", 1, 100000, 400));
  d.timing_frames = static_cast<int>(args.integer("timing-frames", 1, 1000, 3));
  d.placement = probe_placement_from(args, runtime::ProbeVolumeMode::Cascades);
  d.backend = transgi::gpu::make_ddgi_backend(args.choice("backend", {"cpu", "vulkan"}, "cpu"), args.str("device", std::string()));
  const eval::MethodRun r = eval::run_ddgi(scene, width, height, d);
  write_passes(o, r.full, r.direct, r.gi);
  std::printf("rendered %s (ddgi, %s pass) %dx%d at %d spp\n", o.out.c_str(), o.pass.c_str(), width, height, d.render.gbuffer_spp);
  std::printf("probe kernels: %s\n", r.backend.c_str());
  print_stages(r, std::min(d.timing_frames, d.frames));
  return 0;
}

int render_reference(const Args& args, eval::LoadedScene& scene, int width, int height, const Outputs& o) {
  ecs::World& world = scene.app->world();
  const auto& assets = world.resource<scene::SceneAssets>();
  const auto& rt_scene = world.resource<rt::RtScene>();
  const int spp = static_cast<int>(args.integer("spp", 1, 1'000'000, 64));
  const auto seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  const engine::render::LightSet lights(rt_scene, engine::render::gather_punctual_lights(world),
                                        assets.environment ? &*assets.environment : nullptr);
  if (lights.empty()) std::fprintf(stderr, "warning: the scene has no lights; the image will be black\n");
  const engine::render::CameraRays camera(world.get<scene::Camera>(scene.camera), world.get<transform::WorldTransform>(scene.camera),
                                          width, height);
  // The albedo alone needs only the first hit.
  engine::render::PathTracer tracer(rt_scene, lights, camera, width, height,
                                    engine::render::PathTracerSettings{.max_depth = o.pass == "albedo" ? 0 : 64, .seed = seed});
  std::fprintf(stderr, "%zu emissive triangles, %zu punctual lights, environment %s\n", lights.emissive_triangle_count(),
               lights.punctual_count(), lights.environment() ? "yes" : "no");
  core::ProgressBar bar("render " + std::to_string(width) + "x" + std::to_string(height) + " " + o.pass, static_cast<std::uint64_t>(spp));
  scene.app->jobs().run([&] { tracer.render(spp, [&](int done, int) { bar.update(static_cast<std::uint64_t>(done)); }); });
  bar.finish();
  const SurfacePasses surfaces{tracer.image(engine::render::Pass::Albedo), tracer.image(engine::render::Pass::Textured)};
  write_passes(o, tracer.image(engine::render::Pass::Full), tracer.image(engine::render::Pass::Direct),
               tracer.image(engine::render::Pass::Gi), &surfaces);
  const double seconds = tracer.stats().seconds;
  std::printf("rendered %s (reference, %s pass) %dx%d at %d spp in %.2f s (%.2f Mpaths/s, %d threads)%s\n", o.out.c_str(),
              o.pass.c_str(), width, height, spp, seconds, static_cast<double>(tracer.stats().samples) / seconds * 1e-6,
              scene.app->jobs().thread_count(),
              tracer.stats().discarded_non_finite
                  ? (", " + std::to_string(tracer.stats().discarded_non_finite) + " non-finite samples discarded").c_str()
                  : "");
  return 0;
}

}  // namespace

int run_render(const std::vector<std::string>& argv) {
  const Args args("render", argv, render_option_specs(), kRenderSynopsis);
  const std::string scene_path = args.str("scene");
  const std::string method = args.choice("method", {"reference", "transgi", "ddgi"}, "reference");
  Outputs o;
  o.pass = args.choice("pass", {"full", "direct", "gi", "albedo", "all"}, "full");
  o.out = args.str("out");
  o.png = args.str("png", std::string());
  o.exposure = args.number("exposure", -30, 30, 0.0);
  const int width = static_cast<int>(args.integer("width", 1, 16384, 320));
  const int height = static_cast<int>(args.integer("height", 1, 16384, 180));
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  eval::LoadedScene scene = eval::load_scene(scene_path, args.str("camera", std::string()), threads);
  apply_sun_options(args, scene);
  if (o.pass == "albedo" && method != "reference") throw std::runtime_error("--pass albedo: only --method reference writes an albedo pass");
  if (method == "transgi") return render_transgi(args, scene, width, height, o);
  if (method == "ddgi") return render_ddgi(args, scene, width, height, o);
  return render_reference(args, scene, width, height, o);
}

}  // namespace transgi::cli
