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
  const auto model = transgi::model::load_model(model_path);
  if (transfer == "network") transgi::model::validate_model(model, assets, model_path);
  const engine::render::CameraRays camera(world.get<scene::Camera>(cam), world.get<transform::WorldTransform>(cam), width, height);
  const auto source = transfer == "network" ? transgi::shading::TransferSource::Network : transgi::shading::TransferSource::GroundTruth;
  const engine::render::LightSet lights(rt_scene, engine::render::gather_punctual_lights(world),
                                        assets.environment ? &*assets.environment : nullptr);

  transgi::shading::TransferRenderResult r;
  std::unique_ptr<transgi::probes::ProbeField> field;
  transgi::probes::ProbeFrameStats probe_totals;
  int frames = 0;
  if (lighting == "environment") {
    const auto light = transgi::shading::project_environment(*assets.environment);
    app.jobs().run([&] {
      r = transgi::shading::render_transfer(rt_scene, assets, model, camera, width, height,
                                            transgi::shading::constant_light(light), &*assets.environment, source, rs);
    });
  } else {
    frames = static_cast<int>(args.integer("frames", 1, 100000, 32));
    const int n = static_cast<int>(args.integer("probe-grid", 2, 64, 8));
    transgi::probes::ProbeFieldSettings ps;
    // Probes at the centres of an n^3 partition of the scene bounds.
    const glm::vec3 lo = rt_scene.bounds_min(), hi = rt_scene.bounds_max(), half_cell = (hi - lo) / (2.0f * static_cast<float>(n));
    ps.grid = transgi::probes::ProbeGrid{lo + half_cell, hi - half_cell, glm::ivec3(n)};
    ps.rays_per_probe = static_cast<int>(args.integer("probe-rays", 1, 100000, 100));
    ps.seed = rs.seed + 1;
    field = std::make_unique<transgi::probes::ProbeField>(ps);
    core::ProgressBar bar("probe frames", static_cast<std::uint64_t>(frames));
    app.jobs().run([&] {
      for (int f = 0; f < frames; ++f) {
        const auto st = field->update(rt_scene, lights);
        probe_totals.scatter_ms += st.scatter_ms;
        probe_totals.raster_ms += st.raster_ms;
        probe_totals.project_ms += st.project_ms;
        bar.update(static_cast<std::uint64_t>(f + 1));
      }
    });
    bar.finish();
    const auto light_at = [&](const glm::vec3& p, const glm::vec3& nrm, float* o) { field->interpolate(p, nrm, o); };
    app.jobs().run([&] { r = transgi::shading::render_transfer(rt_scene, assets, model, camera, width, height, light_at, nullptr, source, rs); });
  }

  image::ImageRGB img = r.image;
  if (lighting == "probes" && pass_name != "gi") {
    // Direct light: the reference path tracer stopped after its first bounce.
    const int direct_spp = static_cast<int>(args.integer("direct-spp", 1, 100000, 16));
    engine::render::PathTracer direct(rt_scene, lights, camera, width, height,
                                      engine::render::PathTracerSettings{.max_depth = 1, .seed = rs.seed});
    app.jobs().run([&] { direct.render(direct_spp); });
    const image::ImageRGB d = direct.image(engine::render::Pass::Direct);
    if (pass_name == "direct") img = d;
    else
      for (std::size_t i = 0; i < img.size(); ++i) img.pixels[i] += d.pixels[i];
  }
  image::write_exr(out, img);
  if (args.has("png")) image::write_png_srgb(args.str("png"), img, static_cast<float>(exposure));
  if (args.has("coefficient-maps")) {
    const std::string prefix = args.str("coefficient-maps");
    const char* names[3] = {"_sh00.exr", "_sh10.exr", "_sh20.exr"};
    for (int i = 0; i < 3; ++i) image::write_exr(prefix + names[i], r.coefficient_maps[static_cast<std::size_t>(i)]);
  }
  std::printf("rendered %s (transgi, %s transfer, %s light, %s pass) %dx%d at %d spp: %zu shaded samples\n", out.c_str(),
              transfer.c_str(), lighting == "probes" ? "probe" : "environment SH", pass_name.c_str(), width, height, rs.spp,
              r.shaded_samples);
  std::printf("  stage times (ms): G-buffer %.2f, generate network input %.2f, network inference %.2f, SH multiplication %.2f\n",
              r.timings.gbuffer_ms, r.timings.inputs_ms, r.timings.inference_ms, r.light_ms + r.timings.shading_ms);
  if (frames > 0)
    std::printf("  probes: %d frames; per frame (ms): collect shaded points %.2f, probe raster %.2f, SH projection %.2f\n", frames,
                probe_totals.scatter_ms / frames, probe_totals.raster_ms / frames, probe_totals.project_ms / frames);
  return 0;
}

}  // namespace

int run_render(const std::vector<std::string>& argv) {
  const Args args("render", argv,
                  {"scene", "method", "pass", "spp", "width", "height", "out", "camera", "seed", "threads", "png", "exposure",
                   "model", "transfer", "gt-rays", "coefficient-maps", "lighting", "frames", "probe-grid", "probe-rays",
                   "direct-spp"});
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

  // --pass all writes OUT (full), OUT_direct.exr and OUT_gi.exr from the same samples.
  auto sibling = [](const std::string& path, const std::string& suffix) {
    const std::filesystem::path p(path);
    return (p.parent_path() / (p.stem().string() + suffix + p.extension().string())).string();
  };
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
