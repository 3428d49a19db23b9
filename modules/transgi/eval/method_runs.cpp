#include "eval/method_runs.h"

#include "engine/render/light_plugin.h"

#include <algorithm>
#include <array>
#include <cstdio>

#include "engine/core/progress.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/gltf_loader.h"

namespace transgi::eval {

namespace {

using namespace engine;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Per-stage samples of the timed frames -> named medians.
std::vector<Stage> medians(const std::vector<std::string>& names, const std::vector<std::vector<double>>& samples) {
  std::vector<Stage> out;
  for (std::size_t k = 0; k < names.size(); ++k) {
    std::vector<double> v;
    for (const auto& s : samples) v.push_back(s[k]);
    out.push_back({names[k], median(v)});
  }
  return out;
}

double median_total(const std::vector<std::vector<double>>& samples, std::size_t stages_without_direct) {
  std::vector<double> totals;
  for (const auto& s : samples) {
    double t = 0;
    for (std::size_t k = 0; k < stages_without_direct; ++k) t += s[k];
    totals.push_back(t);
  }
  return median(totals);
}

// Runs `frames` App frames; the frame's image is requested (frame.width /
// height set) on the last `imaged` ones (at least `timed`), and after each of
// the last `timed` `sample` collects that frame's stage times. `after_frame`
// sees every frame.
template <class Frame, class Sample, class AfterFrame>
std::vector<std::vector<double>> run_frames(LoadedScene& scene, Frame& frame, int width, int height, int frames, int timed,
                                            int imaged, const std::string& label, bool progress, Sample&& sample,
                                            AfterFrame&& after_frame) {
  timed = std::clamp(timed, 1, frames);
  imaged = std::clamp(imaged, timed, frames);
  core::ProgressBar bar(label, static_cast<std::uint64_t>(frames), progress);
  std::vector<std::vector<double>> samples;
  for (int f = 0; f < frames; ++f) {
    const bool render = f >= frames - imaged;
    frame.width = render ? width : 0;
    frame.height = render ? height : 0;
    scene.app->jobs().run([&] { scene.app->update(); });
    after_frame();
    if (f >= frames - timed) samples.push_back(sample());
    bar.update(static_cast<std::uint64_t>(f + 1));
  }
  bar.finish();
  return samples;
}

}  // namespace

LoadedScene load_scene(const std::string& path, const std::string& camera_name, int threads) {
  LoadedScene s;
  s.app = std::make_unique<app::App>(app::AppOptions{.jobs = {.threads = threads}});
  s.app->add_plugin<rt::RtPlugin>();
  const auto loaded = scene::load_gltf(s.app->world(), path);
  for (const auto& w : loaded.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  s.entities = loaded.entities;
  s.app->update();
  ecs::World& world = s.app->world();
  bool found = false;
  for (ecs::Entity e : loaded.entities) {
    if (!world.has<scene::Camera>(e)) continue;
    if (camera_name.empty() || world.get<scene::Name>(e).value == camera_name) {
      s.camera = e;
      found = true;
      break;
    }
  }
  if (!found) {
    if (camera_name.empty()) throw std::runtime_error(path + ": the scene has no perspective camera");
    throw std::runtime_error("--camera: no camera node named '" + camera_name + "' in " + path);
  }
  return s;
}

MethodRun run_transgi(LoadedScene& scene, const std::shared_ptr<const model::TransferModel>& model, int width, int height,
                      const TransgiRunOptions& o) {
  ecs::World& world = scene.app->world();
  scene.app->add_plugin<runtime::TransGIPlugin>(o.settings, o.host_gpu);
  runtime::attach_latent_meshes(world, model);
  for (const std::string& name : o.no_latent) {
    std::vector<ecs::Entity> matches;
    world.view<const scene::Name, const runtime::LatentMesh>().each(
        [&](ecs::Entity e, const scene::Name& nm, const runtime::LatentMesh&) {
          if (nm.value == name) matches.push_back(e);
        });
    if (matches.empty()) throw std::runtime_error("--no-latent: no mesh node named '" + name + "'");
    for (ecs::Entity e : matches) world.remove<runtime::LatentMesh>(e);
  }
  runtime::spawn_probes(world, o.placement);

  auto& frame = world.resource<runtime::GiFrame>();
  frame.camera = scene.camera;
  frame.antialias_passes = true;  // the passes are what render and eval write and measure
  int traced = 0;
  const auto samples = run_frames(
      // The temporal antialiasing's history builds over the frames that
      // make an image, as in a game: every frame makes one then. The quality
      // path's still-view mean needs its whole window imaged: with only the
      // timed frames it averaged 3 of its 16 jittered samples.
      scene, frame, width, height, o.frames, o.timing_frames,
      o.settings.taa.enabled ? o.frames : std::max(o.timing_frames, o.settings.temporal_window),
      "TransGI probe frames", o.progress,
      [&] {
        const auto& t = frame.times;
        return std::vector<double>{t.gbuffer + t.network_input, t.inference, t.collect_points, t.probe_raster,
                                   t.probe_projection, t.sh_multiplication, t.upsample, t.reflections, t.direct};
      },
      [&] { traced += frame.probe_stats.traced; });
  MethodRun r;
  r.gi = frame.gi;
  r.direct = frame.direct;
  r.full = frame.full;
  r.shaded_samples = frame.shaded_samples;
  r.inferred_samples = frame.inferred_samples;
  r.gpu_submissions = frame.gpu_submissions;
  r.backend = frame.backend + (frame.backend_fallback.empty() ? "" : "; " + frame.backend_fallback);
  r.stages = medians({"generate network input", "network inference", "collect shaded points", "probe raster",
                      "probe accumulation + SH projection", "SH multiplication", "GI upsampling", "reflections", "direct light"},
                     samples);
  r.frame_ms = median_total(samples, 8);
  world.view<const runtime::ProbeVolume>().each([&](const runtime::ProbeVolume& v) {
    if (v.field) r.probe_bytes += v.field->memory_bytes();
  });
  world.view<const runtime::ProbeCascades>().each([&](const runtime::ProbeCascades& c) {
    for (const auto& f : c.state.fields)
      if (f) r.probe_bytes += f->memory_bytes();
  });
  bool fitted_to_scene = false, with_far_field = false;
  world.view<const runtime::ProbeCascades>().each([&](const runtime::ProbeCascades& c) {
    fitted_to_scene = fitted_to_scene || c.state.fitted_to_scene;
    with_far_field = with_far_field || (c.state.fitted_to_scene && c.state.far_field);
  });
  const auto& st = frame.probe_stats;
  char line[256];
  if (o.placement.mode == runtime::ProbeVolumeMode::Scene)
    std::snprintf(line, sizeof(line), "%d^3 probes over the scene's bounds", o.placement.scene_dims.x);
  else if (o.placement.mode == runtime::ProbeVolumeMode::Authored)
    std::snprintf(line, sizeof(line), "the scene's authored probe volumes");
  else if (fitted_to_scene)
    std::snprintf(line, sizeof(line), "cascades: the scene fits one %dx%dx%d grid over its %s (--cascade-fit-scene)",
                  o.placement.cascades.dims.x, o.placement.cascades.dims.y, o.placement.cascades.dims.z,
                  with_far_field ? "geometry less its ground plane, the far field beyond" : "bounds");
  else
    std::snprintf(line, sizeof(line), "%d cascades of %dx%dx%d probes, %.2f m finest cells", o.placement.cascades.count,
                  o.placement.cascades.dims.x, o.placement.cascades.dims.y, o.placement.cascades.dims.z,
                  static_cast<double>(o.placement.cascades.finest_cell));
  r.probe_summary = line;
  std::snprintf(line, sizeof(line), ", %d frames; last frame %d active, %d converged, %d buried, %d far; %.1f traced per frame",
                o.frames, st.active, st.converged, st.buried, st.far, static_cast<double>(traced) / o.frames);
  r.probe_summary += line;
  for (std::size_t k = 0; k < frame.cascade_stats.size(); ++k) {
    const auto& c = frame.cascade_stats[k];
    std::snprintf(line, sizeof(line), "; cascade %zu: %d active, %d buried, %d far", k, c.active, c.buried, c.far);
    r.probe_summary += line;
  }
  std::snprintf(line, sizeof(line), "; probe state %.1f MB", static_cast<double>(r.probe_bytes) / (1024.0 * 1024.0));
  r.probe_summary += line;
  // Say when the sun was taken out of the sky: a user comparing direct
  // light should know it is a directional light now.
  const auto& lights = world.resource<render::SceneLights>();
  if (lights.sun_split && lights.sun_split->sun) {
    const scene::ExtractedSun& sun = *lights.sun_split->sun;
    std::snprintf(line, sizeof(line), "; sun split out of the sky: direction (%.3f, %.3f, %.3f), %.1f deg radius, irradiance (%.3g, %.3g, %.3g) W/m^2",
                  static_cast<double>(sun.direction.x), static_cast<double>(sun.direction.y), static_cast<double>(sun.direction.z),
                  static_cast<double>(glm::degrees(sun.angular_radius)), static_cast<double>(sun.irradiance.r),
                  static_cast<double>(sun.irradiance.g), static_cast<double>(sun.irradiance.b));
    r.probe_summary += line;
  }
  return r;
}

MethodRun run_ddgi(LoadedScene& scene, int width, int height, const DdgiRunOptions& o) {
  ecs::World& world = scene.app->world();
  scene.app->add_plugin<ddgi::DdgiPlugin>(o.settings, o.render);
  world.resource<ddgi::DdgiBackend>() = o.backend;
  // The same placement as TransGI's, so both compare on the same probes.
  if (o.placement.mode != runtime::ProbeVolumeMode::Scene) {
    const auto boxes = runtime::authored_boxes(world);
    if (boxes.empty() && o.placement.mode == runtime::ProbeVolumeMode::Authored)
      throw std::runtime_error("--probe-volume authored: the scene has no node whose extras." + std::string(runtime::kProbeVolumeMarker) + " is set");
    for (const auto& b : boxes) world.emplace<ddgi::DdgiProbeVolume>(b.node, ddgi::DdgiProbeVolume{.min = b.min, .max = b.max, .dims = b.dims});
  }
  if (o.placement.mode == runtime::ProbeVolumeMode::Scene)
    world.emplace<ddgi::DdgiProbeVolume>(world.spawn(), ddgi::DdgiProbeVolume{.dims = o.placement.scene_dims});
  else if (o.placement.mode == runtime::ProbeVolumeMode::Cascades)
    world.emplace<ddgi::DdgiCascades>(world.spawn(), ddgi::DdgiCascades{.cascades = o.placement.cascades});
  auto& frame = world.resource<ddgi::DdgiFrame>();
  frame.camera = scene.camera;
  const auto samples = run_frames(
      scene, frame, width, height, o.frames, o.timing_frames, std::max(o.timing_frames, o.render.temporal_window),
      "DDGI probe updates", o.progress,
      [&] { return std::vector<double>{frame.times.probe_trace, frame.times.probe_blend, frame.times.shading, frame.times.direct}; },
      [] {});
  MethodRun r;
  r.gi = frame.gi;
  r.direct = frame.direct;
  r.full = frame.full;
  r.stages = medians({"probe update: trace and shade rays", "probe update: blend", "probe interpolation (render)", "direct light"}, samples);
  r.frame_ms = median_total(samples, 3);
  int probes = 0;
  world.view<const ddgi::DdgiProbeVolume>().each([&](const ddgi::DdgiProbeVolume& v) {
    if (v.volume) r.probe_bytes += v.volume->memory_bytes();
    if (v.volume) probes += v.volume->grid().count();
  });
  int cascades = 0;
  bool fitted = false;
  world.view<const ddgi::DdgiCascades>().each([&](const ddgi::DdgiCascades& c) {
    fitted = fitted || c.state.fitted_to_scene;
    for (const auto& f : c.state.fields) {
      r.probe_bytes += f->memory_bytes();
      probes += f->grid().count();
      ++cascades;
    }
  });
  char line[200];
  std::snprintf(line, sizeof(line), "%s: %d probes, %d rays, %d updates, %d inactive", runtime::name_of(o.placement.mode).data(),
                probes, o.settings.rays_per_probe, o.frames, frame.probe_stats.inactive);
  r.probe_summary = line;
  if (cascades > 0) {
    std::snprintf(line, sizeof(line), fitted ? " (the scene fits one grid)" : " (%d cascades)", cascades);
    r.probe_summary += line;
  }
  r.backend = world.resource<ddgi::DdgiBackend>().describe();
  r.gpu_submissions = frame.gpu_submissions;
  return r;
}

}  // namespace transgi::eval
