#include "eval/reference_cache.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include "engine/core/fnv1a.h"
#include "engine/core/progress.h"
#include "engine/image/exr.h"
#include "engine/io/atomic_file.h"
#include "engine/render/path_tracer.h"
#include "engine/scene/components.h"
#include "engine/scene/scene_assets.h"
#include "eval/scene_fingerprint.h"

namespace transgi::eval {

namespace {

using namespace engine;

// Bump when the path tracer changes what it computes.
constexpr std::uint64_t kReferenceVersion = 1;

render::PathTracer make_tracer(LoadedScene& scene, const render::LightSet& lights, int width, int height, std::uint64_t seed) {
  ecs::World& world = scene.app->world();
  const render::CameraRays camera(world.get<scene::Camera>(scene.camera), world.get<transform::WorldTransform>(scene.camera), width,
                                  height);
  return render::PathTracer(world.resource<rt::RtScene>(), lights, camera, width, height, render::PathTracerSettings{.seed = seed});
}

render::LightSet scene_lights(LoadedScene& scene) {
  ecs::World& world = scene.app->world();
  const auto& assets = world.resource<scene::SceneAssets>();
  return render::LightSet(world.resource<rt::RtScene>(), render::gather_punctual_lights(world),
                          assets.environment ? &*assets.environment : nullptr);
}

}  // namespace

ReferenceImages reference_images(LoadedScene& scene, int width, int height, int spp, std::uint64_t seed,
                                 const std::filesystem::path& cache_dir, bool progress) {
  ReferenceImages r;
  core::Fnv1a key;
  for (std::uint64_t v : {scene_fingerprint(scene.app->world()), kReferenceVersion, static_cast<std::uint64_t>(width),
                          static_cast<std::uint64_t>(height), static_cast<std::uint64_t>(spp), seed})
    key.value(v);
  r.key = hex64(key.h);
  const auto path = [&](const char* pass) { return cache_dir / ("reference-" + r.key + "_" + pass + ".exr"); };
  const auto meta = cache_dir / ("reference-" + r.key + ".txt");
  if (std::filesystem::exists(meta)) {
    try {
      r.full = image::read_exr(path("full"));
      r.direct = image::read_exr(path("direct"));
      r.gi = image::read_exr(path("gi"));
      std::ifstream in(meta);
      in >> r.spp >> r.seconds;
      if (r.full.width == width && r.full.height == height && r.spp == spp) {
        r.from_cache = true;
        return r;
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "warning: ignoring the cached reference %s: %s\n", meta.string().c_str(), e.what());
    }
  }
  const render::LightSet lights = scene_lights(scene);
  render::PathTracer tracer = make_tracer(scene, lights, width, height, seed);
  core::ProgressBar bar("reference " + std::to_string(width) + "x" + std::to_string(height) + " at " + std::to_string(spp) + " spp",
                        static_cast<std::uint64_t>(spp), progress);
  scene.app->jobs().run([&] { tracer.render(spp, [&](int done, int) { bar.update(static_cast<std::uint64_t>(done)); }); });
  bar.finish();
  r.full = tracer.image(render::Pass::Full);
  r.direct = tracer.image(render::Pass::Direct);
  r.gi = tracer.image(render::Pass::Gi);
  r.spp = spp;
  r.seconds = tracer.stats().seconds;
  std::filesystem::create_directories(cache_dir);
  image::write_exr(path("full"), r.full);
  image::write_exr(path("direct"), r.direct);
  image::write_exr(path("gi"), r.gi);
  // Written last: its presence says the three images are complete.
  const std::string text = std::to_string(spp) + " " + std::to_string(r.seconds) + "\n";
  io::write_file_atomically(meta, std::as_bytes(std::span(text.data(), text.size())));
  return r;
}

image::ImageRGB path_traced_gi(LoadedScene& scene, int width, int height, int spp, std::uint64_t seed, double* seconds) {
  const render::LightSet lights = scene_lights(scene);
  render::PathTracer tracer = make_tracer(scene, lights, width, height, seed);
  scene.app->jobs().run([&] { tracer.render(spp); });
  if (seconds) *seconds = tracer.stats().seconds;
  return tracer.image(render::Pass::Gi);
}

}  // namespace transgi::eval
