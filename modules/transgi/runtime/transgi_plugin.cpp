#include "runtime/transgi_plugin.h"

#include <chrono>
#include <optional>
#include <span>

#include "engine/gpu/gpu_error.h"
#include "engine/jobs/parallel_for.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"
#include "shading/realtime_direct.h"
#include "shading/realtime_gi.h"
#include "engine/render/temporal_accumulation.h"
#include "shading/transfer_renderer.h"
#include "runtime/probe_sync.h"
#include "probes/cascades.h"

namespace transgi::runtime {

namespace {

using namespace engine;
using namespace engine::schedule;
using transform::WorldTransform;

bool deterministic_direct(const TransGISettings& s) {
  return s.gi_path == GiPath::Realtime && s.direct_light == DirectLight::Deterministic;
}

// The light set splits the sun out of the sky when the direct light is
// deterministic (it shades the sun with one shadow ray); the probes then
// carry the residual sky.
void request_light_settings(Res<TransGISettings> settings, ResMut<render::LightSettings> lights) {
  const bool split = deterministic_direct(*settings);
  if (lights->split_sun != split) lights->split_sun = split;
}

// The GI backend, chosen once when the settings first ask for it; a
// resource, as render_gi traces the G-buffer and decodes with it too. Every
// field runs every stage on it.
struct GiBackendChoice {
  Backend made_for = Backend::Cpu;
  std::string device;
  std::uint32_t shader_generation = 0;
  std::shared_ptr<GiBackend> active = cpu_gi_backend();  // never null
  probes::BackendFallback fallback = probes::BackendFallback::None;
  std::string fallback_why;
  std::shared_ptr<engine::gpu::VulkanContext> host;  // the host engine's device, if it gave one

  // The CPU backend whole from now on, and why.
  void fall_back(probes::BackendFallback reason, std::string why) {
    active = cpu_gi_backend();
    fallback = reason;
    fallback_why = std::move(why);
  }
};

void choose_backend(const TransGISettings& settings, GiBackendChoice& chosen) {
  if (chosen.made_for == settings.backend && chosen.device == settings.gpu_device &&
      chosen.shader_generation == settings.shader_generation)
    return;
  chosen = GiBackendChoice{settings.backend, settings.gpu_device, settings.shader_generation, cpu_gi_backend(),
                        probes::BackendFallback::None, "", chosen.host};
  if (settings.backend != Backend::Vulkan) return;
  probes::BackendFallback reason = probes::BackendFallback::None;
  std::string why;
  if (auto vulkan = make_vulkan_gi_backend(chosen.host, settings.gpu_device, &reason, &why)) chosen.active = std::move(vulkan);
  else chosen.fall_back(reason, why);
}

// Which backend runs the frame, and why the CPU's where a device was asked for.
void report_backend(const GiBackendChoice& backend, GiFrame& frame) {
  frame.backend = backend.active->name();
  frame.backend_fallback_reason = backend.fallback;
  frame.backend_fallback = backend.fallback == probes::BackendFallback::None
                               ? std::string()
                               : std::string("the CPU backend runs the frame (") + probes::to_string(backend.fallback) +
                                     "): " + backend.fallback_why;
}

// Every probe volume's and cascade's update on `kernels`.
probes::ProbeFrameStats update_all_fields(View<Get<ProbeVolume>>& volumes, View<Get<ProbeCascades>>& cascades,
                                          const rt::RtScene& rt, const render::LightSet& lights,
                                          const std::shared_ptr<probes::ProbeKernels>& kernels,
                                          std::vector<probes::ProbeFrameStats>& cascade_stats) {
  probes::ProbeFrameStats total;
  volumes.each([&](ProbeVolume& v) {
    if (!v.field) return;
    v.field->set_kernels(kernels);
    total += v.field->update(rt, lights);
  });
  cascade_stats.clear();
  cascades.each([&](ProbeCascades& set) {
    for (std::size_t k = 0; k < set.state.fields.size(); ++k) {
      // Hits beyond a cascade are lit by the next coarser one.
      const probes::ProbeField* outer = k + 1 < set.state.fields.size() ? set.state.fields[k + 1].get() : nullptr;
      if (!set.state.fields[k]) continue;
      set.state.fields[k]->set_kernels(kernels);
      const probes::ProbeFrameStats st = set.state.fields[k]->update(rt, lights, outer);
      if (cascade_stats.size() <= k) cascade_stats.resize(k + 1);
      cascade_stats[k] += st;
      total += st;
    }
  });
  return total;
}

void update_probes(View<Get<ProbeVolume>> volumes, View<Get<ProbeCascades>> cascades, Res<rt::RtScene> rt,
                   Res<render::SceneLights> lights, Res<TransGISettings> settings, ResMut<GiFrame> frame,
                   ResMut<GiBackendChoice> backend) {
  if (settings->freeze_probes) return;
  choose_backend(*settings, *backend);
  probes::ProbeFrameStats total;
  try {
    total = update_all_fields(volumes, cascades, *rt, lights->set, backend->active->probe_kernels(), frame->cascade_stats);
  } catch (const engine::gpu::GpuError& e) {
    if (backend->active == cpu_gi_backend()) throw;
    // The device cannot hold this scene. Every field runs this frame again,
    // on the CPU: those that finished on the device, or threw after their
    // plan and classification, take a second frame of probe work, which
    // moves their light on as one more frame would.
    backend->fall_back(probes::BackendFallback::SceneTooLarge, e.what());
    total = update_all_fields(volumes, cascades, *rt, lights->set, backend->active->probe_kernels(), frame->cascade_stats);
  }
  report_backend(*backend, *frame);
  frame->probe_stats = total;
  for (const DeviceStageTime& stage : backend->active->take_probe_stage_times()) frame->set_device_stage(stage.name, stage.ms);
  ++frame->probe_frames;
}

using CameraView = View<Get<const scene::Camera, const WorldTransform>>;

// The stochastic direct pass (direct_spp NEE samples per pixel, none at 0),
// then full = gi + direct. Both paths end with it unless the real-time
// path's direct light is deterministic.
void add_stochastic_direct(const rt::RtScene& rt, const render::LightSet& lights, const render::CameraRays& rays,
                           int direct_spp, std::uint64_t seed, GiFrame& frame) {
  const auto t0 = std::chrono::steady_clock::now();
  frame.direct = direct_spp > 0 ? render::render_direct_light(rt, lights, rays, frame.width, frame.height, direct_spp, seed)
                                : image::ImageRGB(frame.width, frame.height);
  frame.times.direct = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void compose_full(GiFrame& frame) {
  if (frame.full.width != frame.gi.width || frame.full.height != frame.gi.height) frame.full = image::ImageRGB(frame.gi.width, frame.gi.height);
  jobs::parallel_for<std::size_t>(0, frame.full.size(), 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) frame.full.pixels[i] = frame.gi.pixels[i] + frame.direct.pixels[i];
  });
}

// The decoder packed for the fused kernel, repacked only when the model
// changes, and the G-buffer storage kept from frame to frame.
struct PackedDecoder {
  std::shared_ptr<const model::TransferModel> model;
  std::unique_ptr<shading::FusedDecoder> decoder;
  shading::GBuffer gbuffer;
  shading::RealtimeGiScratch scratch;
  render::TemporalAccumulation history;  // quality path, still views
  render::TemporalAntialiasing taa;       // realtime path
  // The light set's versions the last frame was rendered with.
  std::uint64_t lights_version = 0, geometry_version = 0;
};

// Realtime path: fills the frame's gi, direct and full images and its stage times.
void render_realtime(const render::CameraRays& rays, const std::shared_ptr<const model::TransferModel>& model,
                     const std::function<bool(Entity)>& has_transfer, std::span<const probes::ProbeField* const> fields,
                     const rt::RtScene& rt, const scene::SceneAssets& assets, const render::LightSet& lights,
                     const TransGISettings& settings, std::uint64_t seed, PackedDecoder& packed, GiFrame& frame,
                     rt::RayBatchTracer* tracer, shading::TransferBatchDecoder* batch_decoder, bool light_changed) {
  if (model && packed.model != model) {
    packed.decoder = std::make_unique<shading::FusedDecoder>(model->decoder);
    packed.model = model;
  }
  // A cut forgets the histories: every cell decoded, no antialiasing history.
  shading::RealtimeGiSettings realtime = settings.realtime;
  if (frame.camera_cut) {
    realtime.reuse_history = false;
    packed.scratch.forget_histories();
    packed.taa.clear();
    frame.camera_cut = false;
  }
  auto t0 = std::chrono::steady_clock::now();
  const bool deterministic = deterministic_direct(settings);
  // The deterministic direct light is shaded tile by tile inside the
  // G-buffer's loop, while each tile is in cache; its time counts there.
  std::optional<shading::DirectTileShader> direct;
  // With a backend's tracer the shadow rays go to it in one batch after the
  // G-buffer, not tile by tile inside it.
  // Last frame's images lend their storage to this frame's (nothing reads
  // them once a new frame starts).
  // The sun's disk pattern shifts with the jitter phase: a still pixel's
  // cycle mean then averages 16 points of the disk where the penumbra is too
  // narrow for the filter (realtime_direct.h, disk_pattern_shift).
  const int pattern_phase = settings.taa.enabled ? packed.taa.next_phase(settings.taa) : 0;
  if (deterministic && !tracer)
    direct.emplace(rt, lights, rays, frame.width, frame.height, std::move(frame.direct), pattern_phase);
  packed.scratch.recycle(std::move(frame.gi));
  const glm::vec2 jitter = settings.taa.enabled ? packed.taa.next_jitter(settings.taa) : glm::vec2(0.0f);
  shading::trace_gbuffer(rt, assets, rays, frame.width, frame.height, packed.gbuffer, direct ? &*direct : nullptr, tracer,
                         jitter, settings.taa.texture_lod_bias_in_use());
  std::optional<engine::image::ImageRGB> batched_direct;
  // The shadow rays were traced with the queued view (queue_camera_view)
  // where the G-buffer took that view; else they are traced here in one batch.
  if (deterministic && tracer)
    batched_direct = shading::shade_direct_realtime(packed.gbuffer, rt, lights, rays, &frame.direct_stats, tracer, pattern_phase);
  // The device's time for the camera and shadow rays just traced; the probe
  // update takes the rest (device_stage::kOtherRays).
  if (tracer) frame.set_device_stage(device_stage::kGbufferRays, tracer->take_device_ms());
  const shading::GBuffer& g = packed.gbuffer;
  frame.times.gbuffer = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  // The direct light of punctual lights and the sun first: the probes' share
  // is added to it as the GI is upsampled.
  t0 = std::chrono::steady_clock::now();
  if (deterministic) frame.direct = direct ? direct->take(packed.gbuffer, &frame.direct_stats) : std::move(*batched_direct);
  const double take_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  shading::RealtimeGiStats st;
  frame.gi = shading::shade_gi_realtime({.gbuffer = g,
                                         .scene = rt,
                                         .assets = assets,
                                         .fields = fields,
                                         .settings = realtime,
                                         .model = model.get(),
                                         .decoder = model ? packed.decoder.get() : nullptr,
                                         .has_transfer = has_transfer,
                                         .batch_decoder = batch_decoder,
                                         .mirror_lights = &lights,
                                         .mirror = settings.mirror,
                                         .near_field = settings.near_field},
                                        {.stats = &st, .direct = deterministic ? &frame.direct : nullptr, .scratch = &packed.scratch});
  if (st.inference_device_ms > 0) frame.set_device_stage(device_stage::kInference, st.inference_device_ms);
  GiStageTimes& t = frame.times;
  t.network_input = 0;  // inside the fused kernel, counted as inference
  t.inference = st.inference_ms;
  t.sh_multiplication = st.rotate_ms + st.light_ms + st.near_ms;
  t.upsample = st.upsample_ms;
  t.reflections = st.reflect_ms;
  frame.shaded_samples = st.grid_samples + st.edge_samples;
  frame.inferred_samples = st.inferred;
  frame.realtime = st;

  if (deterministic)
    t.direct = take_ms;
  else
    add_stochastic_direct(rt, lights, rays, settings.direct_spp, seed, frame);
  compose_full(frame);
  // The image a player sees is antialiased; the gi and direct passes too
  // where the caller asks (GiFrame::antialias_passes).
  if (settings.taa.enabled) {
    t0 = std::chrono::steady_clock::now();
    image::ImageRGB* all[] = {&frame.full, &frame.gi, &frame.direct};
    const std::span<image::ImageRGB* const> layers(all, frame.antialias_passes ? 3 : 1);
    packed.taa.resolve(rays, render::TaaSurfaces{packed.gbuffer.position, packed.gbuffer.guide, packed.gbuffer.entity},
                       render::objects_of(rt), layers, settings.taa, light_changed);
    t.antialiasing = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  } else {
    packed.taa.clear();
  }
}

// Before the probes update: the camera's view queued on the backend's
// device (CameraHitTracer::queue_camera_hits), so that it is drawn with the
// probe rays' submission rather than one of its own; the real-time
// G-buffer then takes it (trace_gbuffer). Only a hint: a G-buffer that asks
// for another view gets that one.
void queue_camera_view(CameraView cameras, Res<rt::RtScene> rt, Res<render::SceneLights> lights, Res<TransGISettings> settings,
                       Res<GiFrame> frame, ResMut<GiBackendChoice> backend, Res<PackedDecoder> packed) {
  if (frame->width <= 0 || frame->height <= 0 || settings->gi_path != GiPath::Realtime) return;
  choose_backend(*settings, *backend);
  const auto rays = render::camera_rays_for(cameras, frame->camera, frame->width, frame->height);
  if (!rays) return;
  shading::queue_realtime_view(backend->active->tracer(), *rt, *rays, packed->taa, settings->taa,
                               deterministic_direct(*settings) ? &lights->set : nullptr);
}

void render_gi(CameraView cameras, View<Get<const ProbeVolume>> volumes, View<Get<const ProbeCascades>> cascades,
               View<Get<const LatentMesh>> latents,
               Res<rt::RtScene> rt, Res<scene::SceneAssets> assets, Res<render::SceneLights> lights,
               Res<TransGISettings> settings, ResMut<GiFrame> frame, ResMut<GiBackendChoice> backend, ResMut<PackedDecoder> packed) {
  if (frame->width <= 0 || frame->height <= 0) return;
  const auto rays = render::camera_rays_for(cameras, frame->camera, frame->width, frame->height);
  if (!rays) throw std::runtime_error("transgi::render_gi: GiFrame asks for an image but the world has no camera");
  // The traffic of the probe updates and this image, whichever path returns;
  // the backend is held, as a fallback below replaces the active one.
  struct RecordTraffic {
    GiFrame& frame;
    std::shared_ptr<GiBackend> backend;
    ~RecordTraffic() {
      const engine::gpu::GpuTraffic t = backend->take_traffic();
      frame.gpu_submissions = t.submissions;
      frame.gpu_upload_bytes = t.host_to_device_bytes;
      frame.gpu_download_bytes = t.device_to_host_bytes;
    }
  } record_traffic{*frame, backend->active};

  // One scene decoder: the model of the first LatentMesh found.
  std::shared_ptr<const model::TransferModel> model;
  latents.each([&](const LatentMesh& l) {
    if (!model) model = l.model;
  });
  static const model::TransferModel kNoModel;
  // In the order shading consults them (probes::fields_at): volumes, which
  // take precedence inside their boxes, then the cascades, finest first.
  std::vector<const probes::ProbeField*> fields;
  volumes.each([&](const ProbeVolume& v) {
    if (v.field) fields.push_back(v.field.get());
  });
  cascades.each([&](const ProbeCascades& set) {
    for (const auto& f : set.state.fields)
      if (f) fields.push_back(f.get());
  });

  shading::TransferRenderSettings rs;
  rs.spp = settings->gbuffer_spp;
  rs.lights = &lights->set;
  rs.mirror = settings->mirror;
  rs.ground_truth_rays = settings->ground_truth_rays;
  rs.seed = settings->seed + frame->probe_frames;
  rs.pattern_seed = settings->seed;
  rs.frame_index = frame->probe_frames;
  rs.has_transfer = [&](Entity e) {
    const LatentMesh* l = latents.try_read<LatentMesh>(e);
    return l && model && l->model == model;
  };
  frame->set_device_stage(device_stage::kGbufferRays, 0.0);
  frame->set_device_stage(device_stage::kInference, 0.0);
  if (settings->gi_path == GiPath::Realtime) {
    shading::TransferBatchDecoder* batch_decoder = nullptr;
    std::string decoder_why;
    if (settings->device_inference && model) batch_decoder = backend->active->transfer_decoder(model, &decoder_why);
    if (!decoder_why.empty()) {
      // update_probes resets backend_fallback each frame, but not while the
      // probes are frozen: say it once.
      const std::string note = "transfer inference on the CPU: " + decoder_why;
      if (frame->backend_fallback.find(note) == std::string::npos)
        frame->backend_fallback += (frame->backend_fallback.empty() ? "" : "; ") + note;
    }
    // Lights or geometry that changed (a moving object's shadow) change
    // pixels that did not move: the antialiasing clamps their history.
    const bool light_changed = lights->version != packed->lights_version || lights->geometry_version != packed->geometry_version;
    packed->lights_version = lights->version;
    packed->geometry_version = lights->geometry_version;
    try {
      render_realtime(*rays, model, rs.has_transfer, fields, *rt, *assets, lights->set, *settings, rs.seed, *packed, *frame,
                      backend->active->tracer(), batch_decoder, light_changed);
    } catch (const engine::gpu::GpuError& e) {
      if (backend->active == cpu_gi_backend()) throw;
      // The device could not make this image (its first use this frame, the
      // probes frozen): the CPU backend makes it, and every frame after it,
      // whole; nothing of the failed image is kept.
      backend->fall_back(probes::BackendFallback::SceneTooLarge, e.what());
      report_backend(*backend, *frame);
      render_realtime(*rays, model, rs.has_transfer, fields, *rt, *assets, lights->set, *settings, rs.seed, *packed, *frame,
                      nullptr, nullptr, light_changed);
    }
    frame->times.collect_points = frame->probe_stats.scatter_ms;
    frame->times.probe_raster = frame->probe_stats.raster_ms;
    frame->times.probe_projection = frame->probe_stats.project_ms;
    return;
  }
  // The volume holding the point (the first one, if none does).
  const shading::LightAt light_at = [&](const glm::vec3& p, const glm::vec3& n, float* out) {
    if (fields.empty()) {
      std::fill_n(out, 75, 0.0f);
      return;
    }
    probes::interpolate_fields(fields, p, n, out);
  };
  rs.near_field = settings->near_field;
  if (!fields.empty())
    rs.probe_spacing_at = [&](const glm::vec3& p) { return probes::fields_at(fields, p).field[0]->placement().min_spacing(); };
  const shading::TransferRenderResult r = shading::render_transfer(
      *rt, *assets, model ? *model : kNoModel, *rays, frame->width, frame->height, light_at, nullptr, settings->transfer, rs);

  GiStageTimes& t = frame->times;
  t.gbuffer = r.timings.gbuffer_ms;
  t.network_input = r.timings.inputs_ms;
  t.inference = r.timings.inference_ms;
  t.sh_multiplication = r.light_ms + r.timings.shading_ms;
  t.collect_points = frame->probe_stats.scatter_ms;
  t.probe_raster = frame->probe_stats.raster_ms;
  t.probe_projection = frame->probe_stats.project_ms;
  frame->shaded_samples = r.shaded_samples;
  frame->inferred_samples = r.inferred_samples;
  frame->gi = render::accumulate(packed->history, r.image,
                                 render::view_key(rays->to_world(), frame->width, frame->height, lights->geometry_version, lights->version),
                                 settings->temporal_window);
  add_stochastic_direct(*rt, lights->set, *rays, settings->direct_spp, rs.seed, *frame);
  compose_full(*frame);
}

}  // namespace

TransGISettings realtime_preset() {
  TransGISettings s;
  s.gi_path = GiPath::Realtime;
  s.gbuffer_spp = 1;
  // 50x25 maps: on the sample level with an object moving, GI RMSE 0.0092
  // against 0.0206 for 100x50 maps and 128 probes, for less probe time
  // (docs/performance.md); docs/results.md found 50x25 on the Pareto front.
  // 128 probes a frame after 24 frames that update all of them (a level
  // starts converged): 0.00954, as good as 192 probes, 4 ms sooner; and half
  // the GI cells decoded a frame, the rest reused (docs/performance.md,
  // 2026-11-24 afternoon).
  s.probes.map = probes::MapLayout{50, 25};
  s.probes.update_budget = 128;
  s.probes.settle_frames = 24;
  // No smaller budget while the lights hold (steady_light_budget): 64 cut
  // the sample level's frame by 3 ms at no cost in its GI error, but on the
  // daylit Breakfast Room with an object moving it raised the GI error by a
  // quarter, a glow on the back wall: fewer probes a frame move the probes'
  // light level (docs/results.md, "the probe budget moves the mean";
  // docs/performance.md, 2026-11-27 noon).
  s.realtime.reuse_history = true;
  // Cells keep their decoded transfer up to 32 frames and only take each
  // frame's light: a quarter of the cells decoded instead of half, at no
  // measurable cost in GI error (docs/performance.md, kept transfer).
  s.realtime.transfer_max_age = 32;
  s.taa.enabled = true;
  s.direct_light = DirectLight::Deterministic;
  s.probes.fixed_pattern = true;  // with the deterministic direct light: no seed anywhere in the image
  // One ray from about 4096 cells a frame, averaged over frames: gives a
  // daylit room the contact light the metre-spaced probes miss (the
  // Breakfast Room on its ground plane lost a fifth of its GI without it),
  // for about 1 ms at 640x360 (docs/image-quality.md, "Daylight on the
  // real-time path"). `--near-field-rays 0` is the paper's probes alone.
  s.near_field.rays = 1;
  s.near_field.cell_budget = 4096;
  return s;
}

TransGISettings quality_preset() { return TransGISettings{}; }

void TransGIPlugin::build(app::App& app) {
  app.add_plugin<render::LightPlugin>();  // Embree mirror and light set, which the probes follow
  ecs::World& w = app.world();
  if (!w.has_resource<TransGISettings>()) w.insert_resource<TransGISettings>(settings_);
  if (!w.has_resource<GiFrame>()) w.insert_resource<GiFrame>();
  if (!w.has_resource<GiBackendChoice>()) w.insert_resource<GiBackendChoice>();
  if (host_gpu_) w.resource<GiBackendChoice>().host = host_gpu_;
  if (!w.has_resource<PackedDecoder>()) w.insert_resource<PackedDecoder>();
  app.add_system(Phase::PostUpdate, "transgi::request_light_settings", request_light_settings);
  app.add_system(Phase::PrepareRender, "transgi::sync_probe_volumes", sync_probe_volumes);
  app.add_system(Phase::PrepareRender, "transgi::sync_probe_cascades", sync_probe_cascades);
  app.add_system(Phase::Render, "transgi::queue_camera_view", queue_camera_view);
  app.add_system(Phase::Render, "transgi::update_probes", update_probes);
  app.add_system(Phase::Render, "transgi::render_gi", render_gi);
}

std::size_t attach_latent_meshes(ecs::World& world, const std::shared_ptr<const model::TransferModel>& model) {
  std::vector<std::pair<ecs::Entity, std::uint32_t>> targets;
  world.view<const scene::MeshInstance>().each([&](ecs::Entity e, const scene::MeshInstance& m) {
    if (m.mesh < model->meshes.size()) targets.emplace_back(e, m.mesh);
  });
  for (const auto& [e, mesh] : targets) world.emplace<LatentMesh>(e, LatentMesh{model, mesh});
  return targets.size();
}

}  // namespace transgi::runtime
