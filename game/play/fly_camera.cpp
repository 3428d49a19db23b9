#include "play/fly_camera.h"

#include <cmath>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/input/input_state.h"
#include "engine/transform/transform.h"

namespace game {

namespace {

using namespace engine;

// Whole-world access: it writes the camera's Transform only on frames that
// move it, which a View over a mutable Transform could not express.
void fly_camera(ecs::World& world) {
  const auto* in = world.try_resource<input::InputState>();
  if (!in) return;
  const auto& time = world.resource<app::Time>();
  std::vector<ecs::Entity> cams;
  world.view<const FlyCamera>().each([&](ecs::Entity e, const FlyCamera&) { cams.push_back(e); });
  for (ecs::Entity e : cams) {
    FlyCamera& fly = *world.try_get_mut<FlyCamera>(e);
    const transform::Transform* tp = world.try_get<transform::Transform>(e);
    if (!tp) continue;
    const transform::Transform& t = *tp;
    if (!fly.initialised) {  // yaw and pitch of the start orientation
      const glm::vec3 f = t.rotation * glm::vec3(0, 0, -1);
      fly.yaw = std::atan2(-f.x, -f.z);
      fly.pitch = std::asin(glm::clamp(f.y, -1.0f, 1.0f));
      fly.initialised = true;
    }
    glm::vec3 move(0.0f);
    if (in->is_down("W")) move.z -= 1;
    if (in->is_down("S")) move.z += 1;
    if (in->is_down("A")) move.x -= 1;
    if (in->is_down("D")) move.x += 1;
    const bool look = in->is_down("mouse_right") && (in->mouse_delta.x != 0 || in->mouse_delta.y != 0);
    if (move == glm::vec3(0.0f) && !look) continue;  // leave the camera untouched: no change, no re-render work
    if (look) {
      fly.yaw -= in->mouse_delta.x * fly.radians_per_pixel;
      fly.pitch = glm::clamp(fly.pitch - in->mouse_delta.y * fly.radians_per_pixel, -1.5f, 1.5f);
    }
    transform::Transform& m = world.get_mut<transform::Transform>(e);  // marks it changed only when it moves
    m.rotation = glm::angleAxis(fly.yaw, glm::vec3(0, 1, 0)) * glm::angleAxis(fly.pitch, glm::vec3(1, 0, 0));
    if (move != glm::vec3(0.0f)) m.translation += m.rotation * glm::normalize(move) * fly.speed * static_cast<float>(time.delta_seconds);
  }
}

}  // namespace

void add_fly_camera_system(app::App& app) { app.add_system(schedule::Phase::Update, "game::fly_camera", fly_camera); }

}  // namespace game
