#pragma once
// A small sunlit level for the real-time frame's tests (realtime_direct_test,
// frame_history_test): a 6 m floor and a cube under a blue sky with a 3
// degree sun, the TransGI plugin on the given settings, no model (every
// surface takes the probes' diffuse light).
#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/scene/procedural.h"
#include "lambert.h"
#include "runtime/transgi_plugin.h"

namespace transgi_test {

using namespace transgi;
using namespace engine;

// Blue sky of radiance 0.4 over a dark ground, a 3 degree sun at 40 degrees
// elevation 2500 times brighter.
inline image::ImageRGB sky_with_sun() {
  image::ImageRGB img(128, 64);
  const glm::vec3 sun = glm::normalize(glm::vec3(0.6f, 0.64f, -0.4f));
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const glm::vec3 d = scene::Environment::uv_to_direction({(x + 0.5f) / img.width, (y + 0.5f) / img.height});
      glm::vec3 c = d.y > 0 ? glm::vec3(0.3f, 0.4f, 0.6f) : glm::vec3(0.05f);
      if (glm::dot(d, sun) > std::cos(glm::radians(3.0f))) c += glm::vec3(1000.0f, 950.0f, 900.0f);
      img.at(x, y) = c;
    }
  return img;
}

struct SunLevel {
  app::App app;
  ecs::Entity camera;
  ecs::Entity cube;
  SunLevel(runtime::TransGISettings settings, int threads) : app(app::AppOptions{.jobs = {.threads = threads}}) {
    auto& w = app.world();
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({6, 6}, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_box(glm::vec3(0.5f), false, 1))};
    a.materials = {lambert(glm::vec3(0.6f)), lambert({0.8f, 0.5f, 0.3f})};
    a.environment = scene::Environment(sky_with_sun(), 1.0f, glm::mat4(1.0f));
    w.insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<runtime::TransGIPlugin>(settings);
    const ecs::Entity floor = w.spawn();
    w.emplace<transform::Transform>(floor);
    w.emplace<scene::MeshInstance>(floor, scene::MeshInstance{0});
    cube = w.spawn();
    w.emplace<transform::Transform>(cube, transform::Transform::from_translation({-0.5f, 0.5f, 0.3f}));
    w.emplace<scene::MeshInstance>(cube, scene::MeshInstance{1});
    camera = w.spawn();
    transform::Transform ct = transform::Transform::from_translation({0.0f, 2.5f, 3.5f});
    ct.rotation = glm::quatLookAtRH(glm::normalize(glm::vec3(0.0f, 0.2f, 0.0f) - ct.translation), glm::vec3(0, 1, 0));
    w.emplace<transform::Transform>(camera, ct);
    w.emplace<scene::Camera>(camera, scene::Camera{.yfov_radians = 0.9f});
    const ecs::Entity volume = w.spawn();
    w.emplace<runtime::ProbeVolume>(volume, runtime::ProbeVolume{.min = {-3, 0.1f, -3}, .max = {3, 2.5f, 3}, .dims = {6, 3, 6}});
  }
  runtime::GiFrame& frame() { return app.world().resource<runtime::GiFrame>(); }
  void run(int frames, int width, int height) {
    for (int f = 0; f < frames; ++f) {
      frame().width = f + 1 == frames ? width : 0;
      frame().height = f + 1 == frames ? height : 0;
      app.jobs().run([&] { app.update(); });
    }
  }
  // The path tracer's `pass` with the environment as it is.
  image::ImageRGB reference(int width, int height, int spp, render::Pass pass) {
    auto& w = app.world();
    const render::LightSet unsplit(w.resource<rt::RtScene>(), {}, &*w.resource<scene::SceneAssets>().environment);
    const render::CameraRays rays(w.get<scene::Camera>(camera), w.get<transform::WorldTransform>(camera), width, height);
    render::PathTracer pt(w.resource<rt::RtScene>(), unsplit, rays, width, height, render::PathTracerSettings{.seed = 3});
    app.jobs().run([&] { pt.render(spp); });
    return pt.image(pass);
  }
  image::ImageRGB reference_direct(int width, int height, int spp) { return reference(width, height, spp, render::Pass::Direct); }
};

inline runtime::TransGISettings small_realtime(std::uint64_t seed, std::uint64_t probe_seed) {
  runtime::TransGISettings s = runtime::realtime_preset();
  s.probes.map = probes::MapLayout{32, 16};
  s.probes.update_budget = 0;
  s.seed = seed;
  s.probes.seed = probe_seed;
  return s;
}

}  // namespace transgi_test
