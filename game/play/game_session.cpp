#include "play/game_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "ddgi/ddgi_plugin.h"
#include "gpu/shader_path.h"
#include "gpu/vulkan_ddgi_kernels.h"
#include "engine/core/log.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/scene/find_named.h"
#include "engine/script/script_plugin.h"
#include "engine/transform/transform.h"
#include "eval/method_runs.h"
#include "level/level_manifest.h"
#include "level/level_save.h"
#include "model/model_file.h"
#include "play/fly_camera.h"
#include "runtime/probe_placement.h"
#include "runtime/transgi_plugin.h"

namespace game {

namespace fs = std::filesystem;
using engine::ecs::Entity;

GameMethod parse_method(const std::string& name) {
  if (name == "transgi") return GameMethod::TransGI;
  if (name == "ddgi") return GameMethod::Ddgi;
  if (name == "reference") return GameMethod::Reference;
  throw std::runtime_error("method: expected transgi, ddgi or reference, got '" + name + "'");
}

const char* method_name(GameMethod m) {
  switch (m) {
    case GameMethod::TransGI: return "TransGI";
    case GameMethod::Ddgi: return "DDGI";
    case GameMethod::Reference: return "reference";
  }
  return "?";
}

// The progressive reference: restarted whenever the camera, the geometry or
// the lights change, one sample per pixel added per frame otherwise.
struct GameSession::Reference {
  std::unique_ptr<engine::render::PathTracer> tracer;
  engine::transform::Similarity camera;
  std::uint64_t lights_version = UINT64_MAX, geometry_version = UINT64_MAX;
  engine::image::ImageRGB image;
};

GameSession::GameSession(const GameOptions& options) : options_(options), reference_(std::make_unique<Reference>()) {
  if (options_.width < 16 || options_.height < 16 || options_.width > 8192 || options_.height > 8192)
    throw std::runtime_error("--width/--height: must be in [16, 8192], got " + std::to_string(options_.width) + "x" +
                             std::to_string(options_.height));
  if (options_.view != "full" && options_.view != "gi" && options_.view != "direct")
    throw std::runtime_error("--view: expected full, gi or direct, got '" + options_.view + "'");
  if (!fs::exists(options_.scene)) throw std::runtime_error(options_.scene.string() + ": no such scene file");
  const fs::path model_path = options_.model.empty() ? options_.scene.parent_path() / "transgi.tgm" : options_.model;
  fs::path manifest_path = options_.manifest;
  if (manifest_path.empty() && fs::exists(options_.scene.parent_path() / "game.json")) manifest_path = options_.scene.parent_path() / "game.json";

  transgi::eval::LoadedScene scene = transgi::eval::load_scene(options_.scene.string(), {}, options_.threads);
  app_ = std::move(scene.app);
  camera_ = scene.camera;
  engine::ecs::World& world = app_->world();
  world.insert_resource<LevelOrigin>(LevelOrigin{options_.scene});
  // The model was baked for the glTF alone: validate it before the game adds
  // meshes. A glTF without one still plays: every surface is then shaded
  // from the probes (the diffuse fallback) until it is baked.
  std::shared_ptr<const transgi::model::TransferModel> model;
  if (!options_.model.empty() || fs::exists(model_path)) {
    model = std::make_shared<const transgi::model::TransferModel>(transgi::model::load_model(model_path));
    transgi::model::validate_model(*model, world.resource<engine::scene::SceneAssets>(), model_path);
  }
  app_->add_plugin<transgi::runtime::TransGIPlugin>(transgi::runtime::realtime_preset(), options_.host_gpu);
  if (model) transgi::runtime::attach_latent_meshes(world, model);
  // Cascades around the camera; the sample level is small enough that they
  // stand as one grid over it (CascadeSettings::fit_scene_cell).
  transgi::runtime::spawn_probes(world, transgi::runtime::ProbePlacement{});

  engine::script::ScriptSettings script_settings;
  if (!manifest_path.empty()) {
    const LevelManifest manifest = load_manifest(manifest_path);
    apply_manifest(world, manifest);
    script_settings.root = manifest.scripts_dir;
  }
  for (const auto& [name, file] : options_.scripts) {
    const Entity e = engine::scene::find_named(world, name);
    if (e.is_null()) throw std::runtime_error("--script " + name + "=" + file.string() + ": the level has no entity named '" + name + "'");
    if (!fs::exists(file)) throw std::runtime_error("--script " + name + "=" + file.string() + ": no such file");
    world.emplace<engine::script::Script>(e, engine::script::Script{fs::absolute(file).string(), {}});
  }
  app_->add_plugin<engine::script::ScriptPlugin>(script_settings);
  if (!model)
    world.resource<engine::core::Log>().warning(
        "game", "no baked model at " + model_path.string() + ": every surface is shaded from the probes alone (diffuse); bake one with: transgi bake --scene " +
                    options_.scene.string() + " --out " + model_path.string());
  // scene.spawn("prefab") copies the prefab's latents too, so a copy of a baked object keeps its transfer.
  world.resource<engine::script::ScriptRuntime>().add_clone_hook([](engine::ecs::World& w, Entity from, Entity to) {
    if (const auto* l = w.try_get<transgi::runtime::LatentMesh>(from)) w.emplace<transgi::runtime::LatentMesh>(to, *l);
  });
  world.emplace<FlyCamera>(camera_, FlyCamera{});
  add_fly_camera_system(*app_);

  auto& frame = world.resource<transgi::runtime::GiFrame>();
  frame.camera = camera_;
  if (options_.backend != "cpu") set_backend(options_.backend);  // the warm-up runs on it too
  warm_up();
  frame.width = options_.width;
  frame.height = options_.height;
  frame.antialias_passes = options_.view != "full";  // as set_view says
  set_method(options_.method);
}

void GameSession::warm_up() {
  engine::ecs::World& w = world();
  auto& settings = w.resource<transgi::runtime::TransGISettings>();
  const int frames = options_.probe_warmup_frames >= 0 ? options_.probe_warmup_frames : settings.probes.settle_frames;
  if (frames <= 0) return;
  auto& gi = w.resource<transgi::runtime::GiFrame>();
  auto& time = w.resource<engine::app::Time>();
  const bool paused = time.paused;
  time.paused = true;  // scripts start, but no game time passes
  const auto t0 = std::chrono::steady_clock::now();
  gi.width = gi.height = 0;  // the probes update; no image is made
  for (int f = 0; f < frames; ++f) app_->jobs().run([&] { app_->update(); });
  int image_frames = 0;
  if (options_.method == GameMethod::TransGI) {
    // Images made at the game's size and thrown away, every GI cell tracing
    // its contact ray (no budget): loading time, not frame time.
    gi.width = options_.width;
    gi.height = options_.height;
    const int budget = settings.near_field.cell_budget;
    settings.near_field.cell_budget = 0;
    for (; image_frames < options_.image_warmup_frames; ++image_frames) app_->jobs().run([&] { app_->update(); });
    settings.near_field.cell_budget = budget;
  }
  time.paused = paused;
  w.resource<engine::core::Log>().info(
      "game", "warmed up over " + std::to_string(frames) + " probe updates and " + std::to_string(image_frames) + " frames in " +
                  std::to_string(static_cast<int>(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count())) +
                  " ms, before the first frame");
}

void GameSession::set_view(const std::string& view) {
  if (view != "full" && view != "gi" && view != "direct") throw std::runtime_error("view: expected full, gi or direct, got '" + view + "'");
  options_.view = view;
  // A pass shown on its own is antialiased with the full image, or it shows
  // each frame's jittered sample (a fifth of its pixels flickering).
  world().resource<transgi::runtime::GiFrame>().antialias_passes = view != "full";
  if (auto* d = world().try_resource<transgi::ddgi::DdgiRenderOptions>()) d->antialias_passes = view != "full";
  reference_->lights_version = UINT64_MAX;  // re-read the pass
}

namespace {
// DDGI as a game would run it, added on first use (its probes cost time
// every frame): the real-time frame's deterministic direct light
// (DdgiRenderOptions::realtime) plus the sky's and the emitters' light from
// the probes' emitted maps, so its GI view means what the others' do; a
// cold start over the first updates, then a quarter of the probes a frame.
transgi::ddgi::DdgiSettings game_ddgi_settings() {
  transgi::ddgi::DdgiSettings s;
  s.emitted_maps = true;
  s.rays_per_probe = 128;
  s.warmup_frames = 32;
  s.probes_per_update = 128;
  return s;
}
}  // namespace

void GameSession::set_method(GameMethod m) {
  if (m == method_) return;
  method_ = m;
  engine::ecs::World& w = world();
  if (m == GameMethod::Ddgi && !app_->has_plugin("transgi::DdgiPlugin")) {
    app_->add_plugin<transgi::ddgi::DdgiPlugin>(game_ddgi_settings(),
                                                transgi::ddgi::DdgiRenderOptions{.realtime = true, .antialias_passes = options_.view != "full"});
    w.emplace<transgi::ddgi::DdgiProbeVolume>(w.spawn(), transgi::ddgi::DdgiProbeVolume{});
    if (ddgi_backend_ != "cpu") set_backend(ddgi_backend_);  // the backend chosen before DDGI was first shown
  }
  if (auto* d = w.try_resource<transgi::ddgi::DdgiFrame>()) {
    d->camera = camera_;
    d->width = m == GameMethod::Ddgi ? options_.width : 0;
    d->height = m == GameMethod::Ddgi ? options_.height : 0;
  }
  auto& gi = w.resource<transgi::runtime::GiFrame>();  // TransGI's probes keep updating; its image only when shown
  gi.width = m == GameMethod::TransGI ? options_.width : 0;
  gi.height = m == GameMethod::TransGI ? options_.height : 0;
  reference_->tracer.reset();
  // The path tracer restarts whenever a light or an object moves, and the
  // day-night script turns the sun ten times a second: while the reference
  // is shown, game time stands still so that it converges (a photo mode).
  const bool pause = m == GameMethod::Reference;
  if (w.resource<engine::app::Time>().paused != pause) {
    w.resource<engine::app::Time>().paused = pause;
    w.resource<engine::core::Log>().info(
        "game", pause ? "reference view: game time is paused while the path tracer accumulates (scripts see dt = 0)"
                      : "game time runs again");
  }
}

void GameSession::set_backend(const std::string& backend) {
  if (backend != "cpu" && backend != "vulkan") throw std::runtime_error("backend: expected cpu or vulkan, got '" + backend + "'");
  engine::ecs::World& w = world();
  auto& settings = w.resource<transgi::runtime::TransGISettings>();
  settings.backend = backend == "vulkan" ? transgi::runtime::Backend::Vulkan : transgi::runtime::Backend::Cpu;
  ddgi_backend_ = backend;
  if (auto* d = w.try_resource<transgi::ddgi::DdgiBackend>())
    *d = transgi::gpu::make_ddgi_backend(backend, settings.gpu_device, options_.host_gpu);
}

std::vector<std::string> GameSession::reload_shaders() {
  engine::ecs::World& w = world();
  const std::vector<std::string> errors = transgi::gpu::check_module_shaders();
  auto& log = w.resource<engine::core::Log>();
  for (const auto& e : errors) log.error("shaders", e);
  if (!errors.empty()) return errors;
  ++w.resource<transgi::runtime::TransGISettings>().shader_generation;
  set_backend(ddgi_backend_);  // DDGI's kernels, made again
  log.info("shaders", "reloaded from " + transgi::gpu::shader_dir().string());
  return errors;
}

std::string GameSession::backend_status() {
  const auto& f = world().resource<transgi::runtime::GiFrame>();
  return f.backend + (f.backend_fallback.empty() ? "" : " (" + f.backend_fallback + ")");
}

std::vector<GameSession::StageTime> GameSession::stage_times() const {
  const engine::ecs::World& w = app_->world();
  if (method_ == GameMethod::Reference) return {{"path tracing", last_ms_}};
  if (method_ == GameMethod::Ddgi) {
    const auto* d = w.try_resource<transgi::ddgi::DdgiFrame>();
    if (!d) return {};
    return {{"probe rays", d->times.probe_trace}, {"probe blend", d->times.probe_blend}, {"shading", d->times.shading},
            {"G-buffer, direct", d->times.direct}, {"antialiasing", d->times.antialiasing}};
  }
  const auto& t = w.resource<transgi::runtime::GiFrame>().times;
  return {{"G-buffer", t.gbuffer + t.network_input}, {"inference", t.inference}, {"SH light", t.sh_multiplication},
          {"upsample", t.upsample},           {"reflections", t.reflections}, {"direct", t.direct},          {"antialiasing", t.antialiasing},
          {"probe rays", t.collect_points},   {"raster", t.probe_raster},    {"projection", t.probe_projection}};
}

float graph_top(const std::vector<float>& frame_ms) {
  float top = 10.0f;
  for (float v : frame_ms)
    if (std::isfinite(v)) top = std::max(top, v);
  const float decade = std::pow(10.0f, std::floor(std::log10(top)));
  for (float step : {1.0f, 2.0f, 5.0f, 10.0f})
    if (top <= step * decade) return step * decade;
  return 10.0f * decade;
}

int GameSession::reference_spp() const { return reference_->tracer ? reference_->tracer->samples_per_pixel() : 0; }

void GameSession::render_reference() {
  engine::ecs::World& w = world();
  const auto& lights = w.resource<engine::render::SceneLights>();
  const auto* cam_world = w.try_get<engine::transform::WorldTransform>(camera_);
  if (!cam_world) return;
  Reference& r = *reference_;
  if (!r.tracer || !(r.camera == *cam_world) || r.lights_version != lights.version || r.geometry_version != lights.geometry_version) {
    engine::render::CameraRays rays(w.get<engine::scene::Camera>(camera_), *cam_world, options_.width, options_.height);
    r.tracer = std::make_unique<engine::render::PathTracer>(w.resource<engine::rt::RtScene>(), lights.set, rays, options_.width,
                                                             options_.height);
    r.camera = *cam_world;
    r.lights_version = lights.version;
    r.geometry_version = lights.geometry_version;
  }
  app_->jobs().run([&] { r.tracer->render(1); });
  const engine::render::Pass pass = options_.view == "gi"       ? engine::render::Pass::Gi
                                    : options_.view == "direct" ? engine::render::Pass::Direct
                                                                : engine::render::Pass::Full;
  r.image = r.tracer->image(pass);
}

GameSession::~GameSession() {
  if (app_)
    if (auto* rt = app_->world().try_resource<engine::script::ScriptRuntime>()) rt->shutdown(app_->world());
}

engine::ecs::World& GameSession::world() { return app_->world(); }
engine::input::InputState& GameSession::input() { return world().resource<engine::input::InputState>(); }

Entity GameSession::find(const std::string& name) { return engine::scene::find_named(world(), name); }

EditorView GameSession::view() {
  EditorView v;
  const auto* w = world().try_get<engine::transform::WorldTransform>(camera_);
  if (w) v.camera = *w;
  const auto& cam = world().get<engine::scene::Camera>(camera_);
  v.fov_y = cam.yfov_radians;
  v.aspect = static_cast<float>(options_.width) / static_cast<float>(options_.height);
  v.viewport = {static_cast<float>(options_.width), static_cast<float>(options_.height)};
  return v;
}

void GameSession::begin_input() { input().begin_frame(); }

void GameSession::apply(const ReplayEvent& e) {
  engine::input::InputState& in = input();
  if (e.kind == "key_down") in.set_key(e.name, true);
  else if (e.kind == "key_up") in.set_key(e.name, false);
  else if (e.kind == "key_press") {
    in.set_key(e.name, true);
    in.pressed.insert(e.name);
    in.down.erase(e.name);  // released again before the next frame; scripts see pressed()
  } else if (e.kind == "mouse_move") in.move_mouse(e.xy);
  else if (e.kind == "mouse_move_by") in.move_mouse(in.mouse + e.xy);
  else if (e.kind == "mouse_down") in.set_key("mouse_" + e.name, true);
  else if (e.kind == "mouse_up") in.set_key("mouse_" + e.name, false);
  else if (e.kind == "select") {
    const Entity s = find(e.name);
    if (s.is_null()) throw std::runtime_error(e.where() + ": select: no entity named '" + e.name + "'");
    editor_.selected = s;
  } else if (e.kind == "method") {
    set_method(parse_method(e.name));
  } else if (e.kind == "view") {
    set_view(e.name);
  } else if (e.kind == "backend") {
    set_backend(e.name);
  } else if (e.kind == "reload_shaders") {
    reload_shaders();
  } else if (e.kind == "gizmo_mode") editor_.mode = e.name == "rotate" ? GizmoMode::Rotate : GizmoMode::Translate;
  else if (e.kind == "gizmo_grab") {
    const auto px = handle_grab_pixel(world(), editor_, view(), parse_handle(e.name));
    if (!px) throw std::runtime_error(e.where() + ": gizmo_grab " + e.name +
                                      ": the handle is not visible (nothing selected, or edge-on)");
    in.move_mouse(*px);
  } else {
    throw std::runtime_error(e.where() + ": unknown event '" + e.kind + "'");
  }
}

void GameSession::frame() {
  const auto t0 = std::chrono::steady_clock::now();
  update_editor(world(), editor_, input(), view());
  app_->jobs().run([&] { app_->update(); });
  if (method_ == GameMethod::Reference) render_reference();
  last_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ++frames_;
}

const engine::image::ImageRGB& GameSession::image() const {
  if (method_ == GameMethod::Reference && !reference_->image.empty()) return reference_->image;
  if (method_ == GameMethod::Ddgi)
    if (const auto* d = app_->world().try_resource<transgi::ddgi::DdgiFrame>(); d && !d->full.empty())
      return options_.view == "gi" ? d->gi : options_.view == "direct" ? d->direct : d->full;
  const auto& f = app_->world().resource<transgi::runtime::GiFrame>();
  if (options_.view == "gi") return f.gi;
  if (options_.view == "direct") return f.direct;
  return f.full;
}

}  // namespace game
