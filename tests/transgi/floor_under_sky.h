#pragma once
// A large Lambertian floor (albedo a, no specular) under a uniform sky of
// radiance 1: probes above it have an analytic answer (probe_field_test.cpp,
// ddgi_test.cpp).
#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "probes/probe_field.h"

struct FloorUnderSky {
  engine::app::App app{engine::app::AppOptions{.jobs = {.threads = 2}}};
  // `extra`, if given, stands on the floor at `extra_at` (same material).
  // `half`: the floor's half width (rays below the horizon steeper than
  // height / half hit it; the rest pass its edge to the sky).
  explicit FloorUnderSky(float albedo, const engine::scene::MeshAsset* extra = nullptr, glm::vec3 extra_at = glm::vec3(0.0f),
                         float half = 100.0f) {
    using namespace engine;
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({half, half}))};
    if (extra) a.meshes.push_back(std::make_shared<scene::MeshAsset>(*extra));
    material::Material m;
    m.base_color_factor = glm::vec4(albedo, albedo, albedo, 1);
    m.metallic_factor = 0;
    m.specular_factor = 0;
    a.materials = {m};
    a.environment = scene::uniform_environment(glm::vec3(1.0f));
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    const ecs::Entity e = app.world().spawn();
    app.world().emplace<transform::Transform>(e);
    app.world().emplace<scene::MeshInstance>(e, scene::MeshInstance{0});
    if (extra) {
      const ecs::Entity x = app.world().spawn();
      app.world().emplace<transform::Transform>(x, transform::Transform::from_translation(extra_at));
      app.world().emplace<scene::MeshInstance>(x, scene::MeshInstance{1});
    }
    app.update();
  }
};

// Eight probes above the floor (heights 0.5 and 1.5), maps small enough to
// converge fast.
inline transgi::probes::ProbeFieldSettings floor_probe_settings() {
  transgi::probes::ProbeFieldSettings settings;
  settings.grid = transgi::probes::ProbeGrid{{-1, 0.5f, -1}, {1, 1.5f, 1}, {2, 2, 2}};
  settings.map = transgi::probes::MapLayout{32, 16};
  return settings;
}
