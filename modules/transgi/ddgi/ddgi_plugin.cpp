#include "ddgi/ddgi_plugin.h"

#include "engine/gpu/gpu_error.h"

#include <chrono>

#include "ddgi/ddgi_renderer.h"
#include "engine/render/light_plugin.h"
#include "engine/render/temporal_accumulation.h"
#include "engine/render/path_tracer.h"
#include "engine/scene/components.h"
#include "engine/scene/scene_assets.h"
#include "engine/transform/transform.h"
#include "shading/realtime_direct.h"

namespace transgi::ddgi {

namespace {

using namespace engine;
using namespace engine::schedule;
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

using CameraView = View<Get<const scene::Camera, const transform::WorldTransform>>;

void sync_volumes(View<Get<DdgiProbeVolume>> volumes, View<Get<DdgiCascades>> cascades, CameraView cameras,
                  Res<rt::RtScene> rt, Res<DdgiSettings> settings, Res<DdgiFrame> frame) {
  volumes.each([&](DdgiProbeVolume& v) {
    if (v.fits_scene()) {
      v.min = rt->bounds_min();
      v.max = rt->bounds_max();
    }
    const probes::ProbeGrid grid = probes::ProbeGrid::centred_in(v.min, v.max, v.dims);
    if (!v.volume || !(v.volume->grid() == grid) || !(v.volume->settings() == *settings))
      v.volume = std::make_shared<DdgiVolume>(grid, *settings);
  });
  const probes::CascadeViewer viewer = probes::viewer_of(cameras, frame->camera, rt->bounds_min(), rt->bounds_max());
  cascades.each([&](DdgiCascades& set) {
    // The far field (k = count) lights only what no cascade holds.
    const auto settings_for = [&](int k) {
      DdgiSettings s = *settings;
      s.blend_cells = k >= std::max(1, set.cascades.count) ? probes::kFallbackBlendCells : set.cascades.blend_cells;
      // The fitted grid holds the region it was fitted to, up to its faces.
      if (k < 0) s.hold_cells = 0.5f;
      return s;
    };
    probes::follow_camera(
        set.state, set.cascades, viewer, rt->bounds_min(), rt->bounds_max(), [&] { return probes::geometry_core(*rt); },
        [&](const probes::ProbeGrid& grid, int k) { return std::make_shared<DdgiVolume>(grid, settings_for(k)); },
        [&](const DdgiVolume& v, const probes::ProbeGrid&, int k) { return v.settings() == settings_for(k); },
        [&](DdgiVolume& v, glm::ivec3 cells, const DdgiVolume* coarser) { return v.scroll(cells, coarser); },
        [&](DdgiVolume&, bool) {});
  });
}

// With EscapedRays::Environment the sky arrives through escaped rays, so the
// light set used at hits must leave it out.
struct SkylessLights {
  std::uint64_t version = UINT64_MAX;
  render::LightSet set;
};

// Every volume's and cascade's update on `kernels`.
DdgiFrameStats update_all_volumes(View<Get<DdgiProbeVolume>>& volumes, View<Get<DdgiCascades>>& cascades,
                                  const rt::RtScene& rt, const render::LightSet& set, const scene::Environment* sky,
                                  const std::shared_ptr<DdgiKernels>& kernels) {
  DdgiFrameStats total;
  const auto add = [&](const DdgiFrameStats& s) {
    total.rays += s.rays;
    total.inactive += s.inactive;
    total.trace_ms += s.trace_ms;
    total.blend_ms += s.blend_ms;
  };
  volumes.each([&](DdgiProbeVolume& v) {
    if (!v.volume) return;
    v.volume->set_kernels(kernels);
    add(v.volume->update(rt, set, sky));
  });
  cascades.each([&](DdgiCascades& c) {
    const auto& fields = c.state.fields;
    for (std::size_t k = 0; k < fields.size(); ++k) {
      if (!fields[k]) continue;
      fields[k]->set_kernels(kernels);
      add(fields[k]->update(rt, set, sky, k + 1 < fields.size() ? fields[k + 1].get() : nullptr));
    }
  });
  return total;
}

void update_volumes(View<Get<DdgiProbeVolume>> volumes, View<Get<DdgiCascades>> cascades, Res<rt::RtScene> rt, Res<render::SceneLights> lights,
                    Res<DdgiSettings> settings, ResMut<DdgiFrame> frame, ResMut<DdgiBackend> backend, Local<SkylessLights> skyless) {
  const render::LightSet* set = &lights->set;
  const scene::Environment* sky = lights->set.environment();
  if (settings->escaped == EscapedRays::Environment && sky) {
    if (skyless->version != lights->version) {
      skyless->set = render::LightSet(*rt, lights->set.punctual_lights(), nullptr);
      skyless->version = lights->version;
    }
    set = &skyless->set;
  }
  DdgiFrameStats total;
  try {
    total = update_all_volumes(volumes, cascades, *rt, *set, sky, backend->kernels);
  } catch (const engine::gpu::GpuError& e) {
    if (backend->kernels == cpu_ddgi_kernels()) throw;
    // The device cannot hold this scene: every volume runs this frame again
    // on the CPU (one that finished on the device takes a second frame of
    // probe work, as one more frame would).
    backend->fall_back(probes::BackendFallback::SceneTooLarge, e.what());
    total = update_all_volumes(volumes, cascades, *rt, *set, sky, backend->kernels);
  }
  frame->probe_stats = total;
  frame->times.probe_trace = total.trace_ms;
  frame->times.probe_blend = total.blend_ms;
  ++frame->frames;
}

// The offline shape: filtered primary rays, DDGI's light at their hits,
// averaged over still frames, and path-traced direct light.
void render_offline(const rt::RtScene& rt, const render::LightSet& lights, const render::CameraRays& rays,
                    std::span<const DdgiVolume* const> all, DdgiKernels& kernels, std::uint64_t geometry_version,
                    std::uint64_t lights_version, const DdgiRenderOptions& options, render::TemporalAccumulation& history,
                    DdgiFrame& frame) {
  const std::uint64_t seed = options.seed + frame.frames;
  auto t0 = Clock::now();
  frame.gi = render::accumulate(history, kernels.render_gi(rt, all, rays, frame.width, frame.height, {.spp = options.gbuffer_spp, .seed = seed}),
                                render::view_key(rays.to_world(), frame.width, frame.height, geometry_version, lights_version),
                                options.temporal_window);
  frame.times.shading = ms_since(t0);
  t0 = Clock::now();
  frame.direct = options.direct_spp > 0
                     ? render::render_direct_light(rt, lights, rays, frame.width, frame.height, options.direct_spp, seed)
                     : image::ImageRGB(frame.width, frame.height);
  frame.times.direct = options.direct_spp > 0 ? ms_since(t0) : 0.0;
}

// What the real-time shape keeps from frame to frame.
struct DdgiRealtimeScratch {
  shading::GBuffer gbuffer;
  shading::UpsamplingPlan plan;
  render::TemporalAntialiasing taa;
  std::uint64_t lights_version = UINT64_MAX, geometry_version = UINT64_MAX;
};

// The real-time shape (DdgiRenderOptions::realtime): one G-buffer, its
// direct light shaded tile by tile as it is traced, then DDGI's light at its
// pixels.
void render_realtime(const rt::RtScene& rt, const scene::SceneAssets& assets, const render::SceneLights& scene_lights,
                     const render::CameraRays& rays, std::span<const DdgiVolume* const> volumes, DdgiKernels& kernels,
                     const DdgiRenderOptions& options, DdgiRealtimeScratch& scratch, DdgiFrame& frame) {
  const render::LightSet& lights = scene_lights.set;
  shading::GBuffer& g = scratch.gbuffer;
  auto t0 = Clock::now();
  // The sun's disk pattern shifts with the jitter phase, as TransGI's frame does (realtime_direct.h).
  const int pattern_phase = options.taa.enabled ? scratch.taa.next_phase(options.taa) : 0;
  const glm::vec2 jitter = options.taa.enabled ? scratch.taa.next_jitter(options.taa) : glm::vec2(0.0f);
  if (rt::RayBatchTracer* tracer = kernels.tracer()) {
    // A device's: the shadow rays traced with the queued view
    // (queue_camera_view), or in one batch after the G-buffer.
    shading::trace_gbuffer(rt, assets, rays, frame.width, frame.height, g, nullptr, tracer, jitter,
                           options.taa.texture_lod_bias_in_use());
    frame.direct = shading::shade_direct_realtime(g, rt, lights, rays, nullptr, tracer, pattern_phase);
  } else {
    shading::DirectTileShader direct(rt, lights, rays, frame.width, frame.height, {}, pattern_phase);
    shading::trace_gbuffer(rt, assets, rays, frame.width, frame.height, g, &direct, nullptr, jitter,
                           options.taa.texture_lod_bias_in_use());
    frame.direct = direct.take(g);
  }
  frame.times.direct = ms_since(t0);
  t0 = Clock::now();
  DdgiPixels pixels = shade_ddgi_gbuffer(g, volumes, options.upsampling, scratch.plan, kernels);
  frame.gi = std::move(pixels.gi);
  shading::add_image(frame.direct, pixels.emitted);
  frame.times.shading = ms_since(t0);
  frame.full = frame.gi;
  shading::add_image(frame.full, frame.direct);
  t0 = Clock::now();
  if (options.taa.enabled) {
    // Lights or geometry that changed clamp every pixel's history.
    const bool light_changed = scene_lights.version != scratch.lights_version || scene_lights.geometry_version != scratch.geometry_version;
    scratch.lights_version = scene_lights.version;
    scratch.geometry_version = scene_lights.geometry_version;
    image::ImageRGB* all[] = {&frame.full, &frame.gi, &frame.direct};
    const std::span<image::ImageRGB* const> layers(all, options.antialias_passes ? 3 : 1);
    scratch.taa.resolve(rays, render::TaaSurfaces{g.position, g.guide, g.entity}, render::objects_of(rt), layers, options.taa,
                        light_changed);
  } else {
    scratch.taa.clear();
  }
  frame.times.antialiasing = ms_since(t0);
}

// Before the probes update: the real-time camera view queued on the
// backend's device, drawn with the probe rays' submission rather than one
// of its own (TransGI's transgi::queue_camera_view). Only a hint.
void queue_camera_view(CameraView cameras, Res<rt::RtScene> rt, Res<render::SceneLights> lights, Res<DdgiRenderOptions> options,
                       Res<DdgiFrame> frame, ResMut<DdgiBackend> backend, Res<DdgiRealtimeScratch> scratch) {
  if (frame->width <= 0 || frame->height <= 0 || !options->realtime) return;
  const auto rays = render::camera_rays_for(cameras, frame->camera, frame->width, frame->height);
  if (!rays) return;
  shading::queue_realtime_view(backend->kernels->tracer(), *rt, *rays, scratch->taa, options->taa, &lights->set);
}

void render_frame(CameraView cameras, View<Get<const DdgiProbeVolume>> volumes, View<Get<const DdgiCascades>> cascades,
                  Res<rt::RtScene> rt, Res<scene::SceneAssets> assets, Res<render::SceneLights> lights,
                  Res<DdgiRenderOptions> options, ResMut<DdgiFrame> frame, ResMut<DdgiBackend> backend,
                  Local<render::TemporalAccumulation> history, ResMut<DdgiRealtimeScratch> scratch) {
  if (frame->width <= 0 || frame->height <= 0) return;
  const auto rays = render::camera_rays_for(cameras, frame->camera, frame->width, frame->height);
  if (!rays) throw std::runtime_error("ddgi::render: DdgiFrame asks for an image but the world has no camera");
  // The traffic of the probe updates and this image, whichever way it returns.
  struct RecordTraffic {
    DdgiFrame& frame;
    DdgiBackend& backend;
    ~RecordTraffic() {
      const engine::gpu::GpuTraffic t = backend.kernels->take_traffic();
      frame.gpu_submissions = t.submissions;
      frame.gpu_upload_bytes = t.host_to_device_bytes;
      frame.gpu_download_bytes = t.device_to_host_bytes;
    }
  } record_traffic{*frame, *backend};
  // Authored (and scene) volumes first, then cascades finest first.
  std::vector<const DdgiVolume*> all;
  volumes.each([&](const DdgiProbeVolume& v) {
    if (v.volume) all.push_back(v.volume.get());
  });
  cascades.each([&](const DdgiCascades& c) {
    for (const auto& f : c.state.fields)
      if (f) all.push_back(f.get());
  });
  if (all.empty()) throw std::runtime_error("ddgi::render: no DdgiProbeVolume or DdgiCascades in the world");
  const auto render = [&] {
    if (options->realtime) {
      render_realtime(*rt, *assets, *lights, *rays, all, *backend->kernels, *options, *scratch, *frame);
      return;
    }
    render_offline(*rt, lights->set, *rays, all, *backend->kernels, lights->geometry_version, lights->version, *options,
                   *history, *frame);
    frame->full = frame->gi;
    shading::add_image(frame->full, frame->direct);
  };
  try {
    render();
  } catch (const engine::gpu::GpuError& e) {
    if (backend->kernels == cpu_ddgi_kernels()) throw;
    backend->fall_back(probes::BackendFallback::SceneTooLarge, e.what());
    render();  // nothing of this frame's image was kept
  }
}

}  // namespace

void DdgiPlugin::build(app::App& app) {
  app.add_plugin<render::LightPlugin>();
  ecs::World& w = app.world();
  if (!w.has_resource<DdgiSettings>()) w.insert_resource<DdgiSettings>(settings_);
  if (!w.has_resource<DdgiRenderOptions>()) w.insert_resource<DdgiRenderOptions>(options_);
  if (!w.has_resource<DdgiFrame>()) w.insert_resource<DdgiFrame>();
  if (!w.has_resource<DdgiBackend>()) w.insert_resource<DdgiBackend>();
  if (!w.has_resource<DdgiRealtimeScratch>()) w.insert_resource<DdgiRealtimeScratch>();
  app.add_system(Phase::PrepareRender, "ddgi::sync_volumes", sync_volumes);
  app.add_system(Phase::Render, "ddgi::queue_camera_view", queue_camera_view);
  app.add_system(Phase::Render, "ddgi::update_volumes", update_volumes);
  app.add_system(Phase::Render, "ddgi::render", render_frame);
}

}  // namespace transgi::ddgi
