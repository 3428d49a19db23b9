#include "ddgi/ddgi_plugin.h"

#include <chrono>

#include "ddgi/ddgi_renderer.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"

namespace transgi::ddgi {

namespace {

using namespace engine;
using namespace engine::schedule;
using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

void sync_volumes(View<Get<DdgiProbeVolume>> volumes, Res<rt::RtScene> rt, Res<DdgiSettings> settings) {
  volumes.each([&](DdgiProbeVolume& v) {
    if (v.fits_scene()) {
      v.min = rt->bounds_min();
      v.max = rt->bounds_max();
    }
    // Probes at the centres of a dims partition, as TransGI's volumes.
    const glm::ivec3 dims = glm::max(v.dims, glm::ivec3(1));
    const glm::vec3 half_cell = (v.max - v.min) / (2.0f * glm::vec3(dims));
    const probes::ProbeGrid grid{v.min + half_cell, v.max - half_cell, dims};
    if (!v.volume || !(v.volume->grid() == grid) || !(v.volume->settings() == *settings))
      v.volume = std::make_shared<DdgiVolume>(grid, *settings);
  });
}

// With EscapedRays::Environment the sky arrives through escaped rays, so the
// light set used at hits must leave it out.
struct SkylessLights {
  std::uint64_t version = UINT64_MAX;
  render::LightSet set;
};

void update_volumes(View<Get<DdgiProbeVolume>> volumes, Res<rt::RtScene> rt, Res<render::SceneLights> lights,
                    Res<DdgiSettings> settings, ResMut<DdgiFrame> frame, Local<SkylessLights> skyless) {
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
  volumes.each([&](DdgiProbeVolume& v) {
    if (!v.volume) return;
    const DdgiFrameStats s = v.volume->update(*rt, *set, sky);
    total.rays += s.rays;
    total.inactive += s.inactive;
    total.trace_ms += s.trace_ms;
    total.blend_ms += s.blend_ms;
  });
  frame->probe_stats = total;
  frame->times.probe_trace = total.trace_ms;
  frame->times.probe_blend = total.blend_ms;
  ++frame->frames;
}

void render_frame(View<Get<const scene::Camera, const transform::WorldTransform>> cameras, View<Get<const DdgiProbeVolume>> volumes,
                  Res<rt::RtScene> rt, Res<render::SceneLights> lights, Res<DdgiRenderOptions> options, ResMut<DdgiFrame> frame) {
  if (frame->width <= 0 || frame->height <= 0) return;
  const scene::Camera* camera = nullptr;
  const transform::WorldTransform* to_world = nullptr;
  cameras.each([&](Entity e, const scene::Camera& c, const transform::WorldTransform& w) {
    if (!camera || e == frame->camera) {
      camera = &c;
      to_world = &w;
    }
  });
  if (!camera) throw std::runtime_error("ddgi::render: DdgiFrame asks for an image but the world has no camera");
  const DdgiVolume* volume = nullptr;
  volumes.each([&](const DdgiProbeVolume& v) {
    if (!volume && v.volume) volume = v.volume.get();
  });
  if (!volume) throw std::runtime_error("ddgi::render: no DdgiProbeVolume in the world");
  const render::CameraRays rays(*camera, *to_world, frame->width, frame->height);
  const std::uint64_t seed = options->seed + frame->frames;
  auto t0 = Clock::now();
  frame->gi = render_ddgi_gi(*rt, *volume, rays, frame->width, frame->height, {.spp = options->gbuffer_spp, .seed = seed});
  frame->times.shading = ms_since(t0);
  frame->full = frame->gi;
  frame->direct = image::ImageRGB(frame->width, frame->height);
  frame->times.direct = 0;
  if (options->direct_spp > 0) {
    t0 = Clock::now();
    render::PathTracer direct(*rt, lights->set, rays, frame->width, frame->height,
                              render::PathTracerSettings{.max_depth = 1, .seed = seed});
    direct.render(options->direct_spp);
    frame->direct = direct.image(render::Pass::Direct);
    for (std::size_t i = 0; i < frame->full.size(); ++i) frame->full.pixels[i] += frame->direct.pixels[i];
    frame->times.direct = ms_since(t0);
  }
}

}  // namespace

void DdgiPlugin::build(app::App& app) {
  app.add_plugin<render::LightPlugin>();
  ecs::World& w = app.world();
  if (!w.has_resource<DdgiSettings>()) w.insert_resource<DdgiSettings>(settings_);
  if (!w.has_resource<DdgiRenderOptions>()) w.insert_resource<DdgiRenderOptions>(options_);
  if (!w.has_resource<DdgiFrame>()) w.insert_resource<DdgiFrame>();
  app.add_system(Phase::PrepareRender, "ddgi::sync_volumes", sync_volumes);
  app.add_system(Phase::Render, "ddgi::update_volumes", update_volumes);
  app.add_system(Phase::Render, "ddgi::render", render_frame);
}

}  // namespace transgi::ddgi
