#pragma once
// WASD plus mouse-look (while the right button is held) for the camera
// entity, as a plain Update system.
#include "engine/app/app.h"

namespace game {

struct FlyCamera {
  float speed = 1.5f;               // metres per second; higher = faster, harder to place
  float radians_per_pixel = 0.004f;  // mouse-look sensitivity
  float yaw = 0.0f, pitch = 0.0f;   // from the camera's start orientation
  bool initialised = false;
};

void add_fly_camera_system(engine::app::App& app);

}  // namespace game
