#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/app/app.h"
#include "engine/core/progress.h"
#include "engine/image/exr.h"
#include "engine/image/tonemap.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_assets.h"
#include "model/model_file.h"
#include "probes/probe_field.h"
#include "runtime/transgi_plugin.h"
#include "shading/transfer_renderer.h"

namespace transgi::cli {

namespace {

using namespace engine;

// The named camera, or the first one in node order.
ecs::Entity find_camera(ecs::World& world, const std::vector<ecs::Entity>& node_order, const std::string& name) {
  for (ecs::Entity e : node_order) {
    if (!world.has<scene::Camera>(e)) continue;
    if (name.empty() || world.get<scene::Name>(e).value == name) return e;
  }
  if (name.empty()) throw std::runtime_error("the scene has no perspective camera");
  throw std::runtime_error("--camera: no camera node named '" + name + "'");
}

// --pass all writes OUT (full), OUT_direct.exr and OUT_gi.exr from the same samples.
std::string sibling(const std::string& path, const std::string& suffix) {
  const std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
}

void print_summary(const std::string& out, const std::string& transfer, const char* light, const std::string& pass,
                   int width, int height, int spp, std::size_t shaded, std::size_t inferred) {
  std::printf("rendered %s (transgi, %s transfer, %s light, %s pass) %dx%d at %d spp: %zu shaded samples, %zu inferred\n",
              out.c_str(), transfer.c_str(), light, pass.c_str(), width, height, spp, shaded, inferred);
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

// The game's path: the TransGI plugin in an App, --frames frames of probe
// updates, the image rendered on the last one.
transgi::runtime::GiFrame render_with_probes(const Args& args, app::App& app, ecs::Entity cam,
                                             std::shared_ptr<const transgi::model::TransferModel> model, int width,
                                             int height, const transgi::shading::TransferRenderSettings& rs,
                                             bool want_direct) {
  using namespace transgi;
  ecs::World& world = app.world();
  runtime::TransGISettings settings;
  settings.gbuffer_spp = rs.spp;
  settings.seed = rs.seed;
  settings.direct_spp = want_direct ? static_cast<int>(args.integer("direct-spp", 1, 100000, 16)) : 0;
  settings.probes.rays_per_probe = static_cast<int>(args.integer("probe-rays", 1, 100000, 100));
  settings.probes.seed = rs.seed + 1;
  const std::string skip = args.choice("probe-skip", {"on", "off"}, "on");
  settings.probes.skip.classify = settings.probes.skip.skip_converged = skip == "on";
  const std::string sharing = args.choice("sharing", {"depth-guard", "paper"}, "depth-guard");
  settings.probes.sharing.mode = sharing == "paper" ? probes::SharingMode::PaperFaithful : probes::SharingMode::DepthGuard;
  const int frames = static_cast<int>(args.integer("frames", 1, 100000, 32));
  const int n = static_cast<int>(args.integer("probe-grid", 1, 64, 8));

  app.add_plugin<runtime::TransGIPlugin>(settings);
  std::size_t attached = runtime::attach_latent_meshes(world, model);
  // --no-latent a,b: those nodes keep no latents (they skip inference).
  for (const std::string& name : split_names(args.str("no-latent", std::string()))) {
    std::vector<ecs::Entity> matches;
    world.view<const scene::Name, const runtime::LatentMesh>().each(
        [&](ecs::Entity e, const scene::Name& nm, const runtime::LatentMesh&) {
          if (nm.value == name) matches.push_back(e);
        });
    if (matches.empty()) throw std::runtime_error("--no-latent: no mesh node named '" + name + "'");
    for (ecs::Entity e : matches) world.remove<runtime::LatentMesh>(e);
    attached -= matches.size();
  }
  const ecs::Entity volume = world.spawn();
  world.emplace<runtime::ProbeVolume>(volume, runtime::ProbeVolume{.dims = glm::ivec3(n)});

  auto& frame = world.resource<runtime::GiFrame>();
  frame.camera = cam;
  // The image is rendered on the last --timing-frames frames (once caches
  // and oneDNN's kernels are warm); stage times are their medians.
  const int timed = std::min(frames, static_cast<int>(args.integer("timing-frames", 1, 1000, 3)));
  core::ProgressBar bar("probe frames", static_cast<std::uint64_t>(frames));
  std::vector<std::array<double, 9>> samples;
  int traced = 0;
  for (int f = 0; f < frames; ++f) {
    const bool render = f >= frames - timed;
    frame.width = render ? width : 0;
    frame.height = render ? height : 0;
    app.jobs().run([&] { app.update(); });
    traced += frame.probe_stats.traced;
    if (render) {
      const auto& t = frame.times;
      samples.push_back({t.gbuffer, t.network_input, t.inference, t.collect_points, t.probe_raster, t.probe_projection,
                         t.sh_multiplication, t.direct, static_cast<double>(frame.probe_stats.traced)});
    }
    bar.update(static_cast<std::uint64_t>(f + 1));
  }
  bar.finish();
  std::array<double, 9> med{};
  for (std::size_t k = 0; k < med.size(); ++k) {
    std::vector<double> v;
    for (const auto& smp : samples) v.push_back(smp[k]);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    med[k] = v[v.size() / 2];
  }
  const auto& st = frame.probe_stats;
  std::printf("  %zu of the scene's mesh entities have a LatentMesh; %zu of %zu shaded samples inferred\n", attached,
              frame.inferred_samples, frame.shaded_samples);
  std::printf("  probes: %d^3, %d frames, last frame: %d active, %d converged, %d buried, %d far; %.1f probes traced per frame\n",
              n, frames, st.active, st.converged, st.buried, st.far, static_cast<double>(traced) / frames);
  std::printf("  Table 4 stages, median of the last %d frames (ms): generate network input %.2f (G-buffer %.2f + inputs %.2f),\n"
              "    network inference %.2f, collect shaded points %.2f, probe raster %.2f (+ accumulate and project %.2f),\n"
              "    SH multiplication %.2f; direct light %.2f; total %.2f\n",
              timed, med[0] + med[1], med[0], med[1], med[2], med[3], med[4], med[5], med[6], med[7],
              med[0] + med[1] + med[2] + med[3] + med[4] + med[5] + med[6] + med[7]);
  return frame;
}

// TransGI rendering. --lighting environment: the object-scale setting (paper
// Fig. 7), the environment projected to SH is the only light. --lighting
// probes: SH light probes with radiance sharing, updated for --frames frames,
// give the GI; --pass full adds direct light (the path tracer stopped after
// the first bounce, --direct-spp samples).
int render_transgi(const Args& args, app::App& app, ecs::Entity cam, int width, int height, const std::string& out,
                   double exposure, const std::string& pass_name) {
  ecs::World& world = app.world();
  const auto& assets = world.resource<scene::SceneAssets>();
  const auto& rt_scene = world.resource<rt::RtScene>();
  const std::string model_path = args.str("model");
  const std::string transfer = args.choice("transfer", {"network", "ground-truth"}, "network");
  const std::string lighting = args.choice("lighting", {"probes", "environment"}, "probes");
  transgi::shading::TransferRenderSettings rs;
  rs.spp = static_cast<int>(args.integer("spp", 1, 4096, 4));
  rs.ground_truth_rays = static_cast<int>(args.integer("gt-rays", 1, 1'000'000, 2048));
  rs.seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  if (lighting == "environment" && !assets.environment)
    throw std::runtime_error("--lighting environment needs an environment light in the scene (scenes[0].extras.environment)");
  auto model = transgi::model::load_model(model_path);
  if (transfer == "network") transgi::model::validate_model(model, assets, model_path);
  const engine::render::CameraRays camera(world.get<scene::Camera>(cam), world.get<transform::WorldTransform>(cam), width, height);
  const auto source = transfer == "network" ? transgi::shading::TransferSource::Network : transgi::shading::TransferSource::GroundTruth;
  transgi::shading::TransferRenderResult r;
  image::ImageRGB img;
  if (lighting == "environment") {
    const auto light = transgi::shading::project_environment(*assets.environment);
    app.jobs().run([&] {
      r = transgi::shading::render_transfer(rt_scene, assets, model, camera, width, height,
                                            transgi::shading::constant_light(light), &*assets.environment, source, rs);
    });
    img = r.image;
    print_summary(out, transfer, "environment SH", pass_name, width, height, rs.spp, r.shaded_samples, r.inferred_samples);
    std::printf("  stage times (ms): G-buffer %.2f, generate network input %.2f, network inference %.2f, SH multiplication %.2f\n",
                r.timings.gbuffer_ms, r.timings.inputs_ms, r.timings.inference_ms, r.light_ms + r.timings.shading_ms);
  } else {
    if (transfer != "network") throw std::runtime_error("--transfer ground-truth needs --lighting environment");
    const auto shared = std::make_shared<const transgi::model::TransferModel>(std::move(model));
    const auto frame = render_with_probes(args, app, cam, shared, width, height, rs, pass_name != "gi");
    print_summary(out, transfer, "probe", pass_name, width, height, rs.spp, frame.shaded_samples, frame.inferred_samples);
    img = pass_name == "gi" ? frame.gi : pass_name == "direct" ? frame.direct : frame.full;
    if (pass_name == "all") {
      image::write_exr(sibling(out, "_direct"), frame.direct);
      image::write_exr(sibling(out, "_gi"), frame.gi);
      if (args.has("png")) {
        image::write_png_srgb(sibling(args.str("png"), "_direct"), frame.direct, static_cast<float>(exposure));
        image::write_png_srgb(sibling(args.str("png"), "_gi"), frame.gi, static_cast<float>(exposure));
      }
    }
  }
  image::write_exr(out, img);
  if (args.has("png")) image::write_png_srgb(args.str("png"), img, static_cast<float>(exposure));
  if (args.has("coefficient-maps")) {
    if (lighting != "environment") throw std::runtime_error("--coefficient-maps needs --lighting environment");
    const std::string prefix = args.str("coefficient-maps");
    const char* names[3] = {"_sh00.exr", "_sh10.exr", "_sh20.exr"};
    for (int i = 0; i < 3; ++i) image::write_exr(prefix + names[i], r.coefficient_maps[static_cast<std::size_t>(i)]);
  }
  return 0;
}

}  // namespace

int run_render(const std::vector<std::string>& argv) {
  const Args args("render", argv,
                  {"scene", "method", "pass", "spp", "width", "height", "out", "camera", "seed", "threads", "png", "exposure",
                   "model", "transfer", "gt-rays", "coefficient-maps", "lighting", "frames", "probe-grid", "probe-rays",
                   "direct-spp", "probe-skip", "sharing", "no-latent", "timing-frames"});
  const std::string scene_path = args.str("scene");
  const std::string method = args.choice("method", {"reference", "transgi"}, "reference");
  const std::string pass_name = args.choice("pass", {"full", "direct", "gi", "all"}, "full");
  const int spp = static_cast<int>(args.integer("spp", 1, 1'000'000, 64));
  const int width = static_cast<int>(args.integer("width", 1, 16384, 320));
  const int height = static_cast<int>(args.integer("height", 1, 16384, 180));
  const std::string out = args.str("out");
  const auto seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  const double exposure = args.number("exposure", -30, 30, 0.0);
  const engine::render::Pass pass = pass_name == "direct" ? engine::render::Pass::Direct : pass_name == "gi" ? engine::render::Pass::Gi : engine::render::Pass::Full;

  app::App app(app::AppOptions{.jobs = {.threads = threads}});
  app.add_plugin<rt::RtPlugin>();
  const auto loaded = scene::load_gltf(app.world(), scene_path);
  for (const auto& w : loaded.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  app.update();  // world transforms + Embree scene

  ecs::World& world = app.world();
  const ecs::Entity cam = find_camera(world, loaded.entities, args.str("camera", std::string()));
  const auto& assets = world.resource<scene::SceneAssets>();
  const auto& rt_scene = world.resource<rt::RtScene>();
  if (method == "transgi") return render_transgi(args, app, cam, width, height, out, exposure, pass_name);
  const engine::render::LightSet lights(rt_scene, engine::render::gather_punctual_lights(world),
                                assets.environment ? &*assets.environment : nullptr);
  if (lights.empty()) std::fprintf(stderr, "warning: the scene has no lights; the image will be black\n");
  const engine::render::CameraRays camera(world.get<scene::Camera>(cam), world.get<transform::WorldTransform>(cam), width, height);
  engine::render::PathTracer tracer(rt_scene, lights, camera, width, height, engine::render::PathTracerSettings{.seed = seed});

  std::fprintf(stderr, "%s: %zu meshes, %zu triangles, %zu emissive triangles, %zu punctual lights, environment %s\n",
               scene_path.c_str(), loaded.mesh_count, loaded.triangle_count, lights.emissive_triangle_count(),
               lights.punctual_count(), lights.environment() ? "yes" : "no");
  core::ProgressBar bar("render " + std::to_string(width) + "x" + std::to_string(height) + " " + pass_name, static_cast<std::uint64_t>(spp));
  app.jobs().run([&] { tracer.render(spp, [&](int done, int) { bar.update(static_cast<std::uint64_t>(done)); }); });
  bar.finish();

  const image::ImageRGB img = tracer.image(pass);
  image::write_exr(out, img);
  if (pass_name == "all") {
    image::write_exr(sibling(out, "_direct"), tracer.image(engine::render::Pass::Direct));
    image::write_exr(sibling(out, "_gi"), tracer.image(engine::render::Pass::Gi));
  }
  if (args.has("png")) {
    image::write_png_srgb(args.str("png"), img, static_cast<float>(exposure));
    if (pass_name == "all") {
      image::write_png_srgb(sibling(args.str("png"), "_direct"), tracer.image(engine::render::Pass::Direct), static_cast<float>(exposure));
      image::write_png_srgb(sibling(args.str("png"), "_gi"), tracer.image(engine::render::Pass::Gi), static_cast<float>(exposure));
    }
  }
  const double seconds = tracer.stats().seconds;
  std::printf("rendered %s (%s, %s pass) %dx%d at %d spp in %.2f s (%.2f Mpaths/s, %d threads)%s\n", out.c_str(),
              method.c_str(), pass_name.c_str(), width, height, spp, seconds,
              static_cast<double>(tracer.stats().samples) / seconds * 1e-6, app.jobs().thread_count(),
              tracer.stats().discarded_non_finite ? (", " + std::to_string(tracer.stats().discarded_non_finite) + " non-finite samples discarded").c_str() : "");
  return 0;
}

}  // namespace transgi::cli
