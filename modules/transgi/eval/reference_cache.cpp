#include "eval/reference_cache.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>
#include <fstream>
#include <sstream>

#include "engine/core/fnv1a.h"
#include "engine/core/progress.h"
#include "engine/image/exr.h"
#include "engine/image/metrics.h"
#include "engine/io/atomic_file.h"
#include "engine/render/path_tracer.h"
#include "engine/scene/components.h"
#include "engine/scene/scene_assets.h"
#include "eval/scene_fingerprint.h"

namespace transgi::eval {

namespace {

using namespace engine;

// Bump when the path tracer changes what it computes.
constexpr std::uint64_t kReferenceVersion = 2;  // 2: two halves, adaptive sampling

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

ReferenceImages reference_images(LoadedScene& scene, int width, int height, const ReferenceOptions& o,
                                 const std::filesystem::path& cache_dir, bool progress) {
  ReferenceImages r;
  core::Fnv1a key;
  std::uint32_t target_bits = 0;
  std::memcpy(&target_bits, &o.target_error, sizeof target_bits);
  for (std::uint64_t v : {scene_fingerprint(scene.app->world()), kReferenceVersion, static_cast<std::uint64_t>(width),
                          static_cast<std::uint64_t>(height), static_cast<std::uint64_t>(o.spp), o.seed, std::uint64_t{target_bits}})
    key.value(v);
  r.key = hex64(key.h);
  r.spp = o.spp;
  r.target_error = o.target_error;
  const auto path = [&](const char* pass) { return cache_dir / ("reference-" + r.key + "_" + pass + ".exr"); };
  const auto meta = cache_dir / ("reference-" + r.key + ".txt");
  if (std::filesystem::exists(meta)) {
    try {
      r.full = image::read_exr(path("full"));
      r.direct = image::read_exr(path("direct"));
      r.gi = image::read_exr(path("gi"));
      std::ifstream in(meta);
      int spp = 0;
      in >> spp >> r.seconds >> r.mean_spp >> r.noise_gi >> r.noise_full;
      if (in && r.full.width == width && r.full.height == height && spp == o.spp) {
        r.from_cache = true;
        return r;
      }
    } catch (const std::exception& e) {
      std::fprintf(stderr, "warning: ignoring the cached reference %s: %s\n", meta.string().c_str(), e.what());
    }
  }
  const render::LightSet lights = scene_lights(scene);
  std::vector<render::PathTracer> halves;
  halves.reserve(2);
  for (int h = 0; h < 2; ++h) {
    const std::uint64_t seed = h == 0 ? o.seed : o.seed ^ 0x9E3779B97F4A7C15ull;
    render::PathTracer& tracer = halves.emplace_back(make_tracer(scene, lights, width, height, seed));
    const std::string label = "reference " + std::to_string(width) + "x" + std::to_string(height) + ", half " + std::to_string(h + 1) + "/2";
    if (o.target_error > 0) {
      render::AdaptiveSampling a;
      a.target_error = o.target_error * std::sqrt(2.0f);
      a.max_spp = std::max(a.min_spp, o.spp / 2);
      core::ProgressBar bar(label + ", adaptive to " + std::to_string(o.target_error) + " (pixels done)",
                            static_cast<std::uint64_t>(width) * height, progress);
      scene.app->jobs().run([&] { tracer.render_adaptive(a, [&](int done, int) { bar.update(static_cast<std::uint64_t>(done)); }); });
      bar.finish();
    } else {
      const int spp = std::max(1, o.spp / 2);
      core::ProgressBar bar(label + " at " + std::to_string(spp) + " spp", static_cast<std::uint64_t>(spp), progress);
      scene.app->jobs().run([&] { tracer.render(spp, [&](int done, int) { bar.update(static_cast<std::uint64_t>(done)); }); });
      bar.finish();
    }
    r.seconds += tracer.stats().seconds;
    r.mean_spp += tracer.mean_samples_per_pixel();
  }
  const auto average = [&](render::Pass pass) {
    image::ImageRGB a = halves[0].image(pass);
    const image::ImageRGB b = halves[1].image(pass);
    for (std::size_t i = 0; i < a.pixels.size(); ++i) a.pixels[i] = 0.5f * (a.pixels[i] + b.pixels[i]);
    return a;
  };
  r.noise_gi = 0.5 * image::compare_images(halves[0].image(render::Pass::Gi), halves[1].image(render::Pass::Gi)).rmse;
  r.noise_full = 0.5 * image::compare_images(halves[0].image(render::Pass::Full), halves[1].image(render::Pass::Full)).rmse;
  r.full = average(render::Pass::Full);
  r.direct = average(render::Pass::Direct);
  r.gi = average(render::Pass::Gi);
  std::filesystem::create_directories(cache_dir);
  image::write_exr(path("full"), r.full);
  image::write_exr(path("direct"), r.direct);
  image::write_exr(path("gi"), r.gi);
  // Written last: its presence says the three images are complete.
  char text[256];
  std::snprintf(text, sizeof text, "%d %.3f %.2f %.9g %.9g\n", o.spp, r.seconds, r.mean_spp, r.noise_gi, r.noise_full);
  io::write_file_atomically(meta, std::as_bytes(std::span(text, std::strlen(text))));
  return r;
}

std::string reference_noise_note(const ReferenceImages& ref, double smallest_error) {
  char line[512];
  std::snprintf(line, sizeof line, "reference noise: RMSE %.4f (gi), %.4f (full), from two independent halves", ref.noise_gi, ref.noise_full);
  std::string s = line;
  if (smallest_error > 0 && ref.noise_gi > smallest_error / 5) {
    std::snprintf(line, sizeof line,
                  "\nwarning: the reference's noise (gi RMSE %.4f) exceeds 1/5 of the smallest error it judges (%.4f): "
                  "errors this close to the noise say little; render a more converged reference (--reference-error)",
                  ref.noise_gi, smallest_error);
    s += line;
  }
  return s;
}

image::ImageRGB path_traced_gi(LoadedScene& scene, int width, int height, int spp, std::uint64_t seed, double* seconds) {
  const render::LightSet lights = scene_lights(scene);
  render::PathTracer tracer = make_tracer(scene, lights, width, height, seed);
  scene.app->jobs().run([&] { tracer.render(spp); });
  if (seconds) *seconds = tracer.stats().seconds;
  return tracer.image(render::Pass::Gi);
}

}  // namespace transgi::eval
