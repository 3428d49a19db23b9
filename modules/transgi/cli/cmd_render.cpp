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

}  // namespace

int run_render(const std::vector<std::string>& argv) {
  const Args args("render", argv,
                  {"scene", "method", "pass", "spp", "width", "height", "out", "camera", "seed", "threads", "png", "exposure"});
  const std::string scene_path = args.str("scene");
  const std::string method = args.choice("method", {"reference"}, "reference");
  const std::string pass_name = args.choice("pass", {"full", "direct", "gi", "all"}, "full");
  const int spp = static_cast<int>(args.integer("spp", 1, 1'000'000, 64));
  const int width = static_cast<int>(args.integer("width", 1, 16384, 320));
  const int height = static_cast<int>(args.integer("height", 1, 16384, 180));
  const std::string out = args.str("out");
  const auto seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  const double exposure = args.number("exposure", -30, 30, 0.0);
  const render::Pass pass = pass_name == "direct" ? render::Pass::Direct : pass_name == "gi" ? render::Pass::Gi : render::Pass::Full;

  app::App app(app::AppOptions{.jobs = {.threads = threads}});
  app.add_plugin<rt::RtPlugin>();
  const auto loaded = scene::load_gltf(app.world(), scene_path);
  for (const auto& w : loaded.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  app.update();  // world transforms + Embree scene

  ecs::World& world = app.world();
  const ecs::Entity cam = find_camera(world, loaded.entities, args.str("camera", std::string()));
  const auto& assets = world.resource<scene::SceneAssets>();
  const auto& rt_scene = world.resource<rt::RtScene>();
  const render::LightSet lights(rt_scene, render::gather_punctual_lights(world),
                                assets.environment ? &*assets.environment : nullptr);
  if (lights.empty()) std::fprintf(stderr, "warning: the scene has no lights; the image will be black\n");
  const render::CameraRays camera(world.get<scene::Camera>(cam), world.get<transform::WorldTransform>(cam), width, height);
  render::PathTracer tracer(rt_scene, lights, camera, width, height, render::PathTracerSettings{.seed = seed});

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
    image::write_exr(sibling(out, "_direct"), tracer.image(render::Pass::Direct));
    image::write_exr(sibling(out, "_gi"), tracer.image(render::Pass::Gi));
  }
  if (args.has("png")) {
    image::write_png_srgb(args.str("png"), img, static_cast<float>(exposure));
    if (pass_name == "all") {
      image::write_png_srgb(sibling(args.str("png"), "_direct"), tracer.image(render::Pass::Direct), static_cast<float>(exposure));
      image::write_png_srgb(sibling(args.str("png"), "_gi"), tracer.image(render::Pass::Gi), static_cast<float>(exposure));
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
