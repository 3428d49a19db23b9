#pragma once
// The real-time GI tests' scene (realtime_gi_test.cpp, gi_history_test.cpp).
#include <cstdint>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"
#include "engine/transform/transform.h"
#include "lambert.h"

namespace transgi_test {

// A saturated orange box in front of a blue wall, on a grey floor, under a
// uniform sky: every silhouette separates two colours, so GI that bleeds
// across one shows as the wrong hue.
struct EdgeScene {
  engine::ecs::Entity floor, box, wall;
  engine::app::App app{engine::app::AppOptions{.jobs = {.threads = 2}}};
  explicit EdgeScene(glm::vec3 box_albedo = {0.95f, 0.4f, 0.05f}) {
    using namespace engine;
    scene::SceneAssets a;
    a.generation = scene::next_scene_generation();
    a.meshes = {std::make_shared<scene::MeshAsset>(scene::make_quad({4, 4}, 0)),
                std::make_shared<scene::MeshAsset>(scene::make_box(glm::vec3(0.4f), false, 1)),
                std::make_shared<scene::MeshAsset>(scene::make_quad({4, 2}, 2))};
    a.materials = {lambert(glm::vec3(0.6f)), lambert(box_albedo), lambert({0.05f, 0.2f, 0.9f})};
    a.environment = scene::uniform_environment(glm::vec3(1.0f));
    app.world().insert_resource<scene::SceneAssets>(std::move(a));
    app.add_plugin<rt::RtPlugin>();
    auto spawn = [&](std::uint32_t mesh, glm::vec3 at, glm::quat rotation) -> ecs::Entity {
      transform::Transform t = transform::Transform::from_translation(at);
      t.rotation = rotation;
      const ecs::Entity e = app.world().spawn();
      app.world().emplace<transform::Transform>(e, t);
      app.world().emplace<scene::MeshInstance>(e, scene::MeshInstance{mesh});
      return e;
    };
    floor = spawn(0, glm::vec3(0.0f), glm::quat(1, 0, 0, 0));
    box = spawn(1, {0, 0.4f, 0}, glm::angleAxis(0.5f, glm::vec3(0, 1, 0)));
    // The wall: the quad (in XZ, facing +Y) stood up at z = -2, facing +Z.
    wall = spawn(2, {0, 2, -2}, glm::angleAxis(1.5707963f, glm::vec3(1, 0, 0)));
    app.update();
  }
};

// The real-time GI tests' camera: at `position`, looking down the -Z axis
// tilted 0.2 rad down onto the box.
inline engine::transform::Similarity camera_at(glm::vec3 position) {
  return engine::transform::Similarity{.translation = position, .rotation = glm::angleAxis(-0.2f, glm::vec3(1, 0, 0))};
}

}  // namespace transgi_test
