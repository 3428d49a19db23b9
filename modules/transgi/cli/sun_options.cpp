#include "cli/sun_options.h"

#include <cstdio>
#include <stdexcept>

#include "engine/scene/sun.h"
#include "engine/transform/transform.h"

namespace transgi::cli {

bool apply_sun_options(const Args& args, eval::LoadedScene& scene) {
  if (!args.has("sun-elevation") && !args.has("sun-azimuth")) return false;
  engine::ecs::World& world = scene.app->world();
  const auto sun = engine::scene::find_sun(world);
  if (!sun) throw std::runtime_error("--sun-elevation/--sun-azimuth: the scene has no directional light (KHR_lights_punctual)");
  const glm::vec3 to_sun = -(world.get<engine::transform::Transform>(*sun).rotation * glm::vec3(0, 0, -1));
  const glm::vec2 now = engine::scene::sun_angles(glm::normalize(to_sun));
  const auto elevation = static_cast<float>(args.number("sun-elevation", -90.0, 90.0, now.x));
  const auto azimuth = static_cast<float>(args.number("sun-azimuth", -360.0, 360.0, now.y));
  engine::scene::set_sun(world, elevation, azimuth);
  scene.app->jobs().run([&] { scene.app->update(); });
  std::printf("sun turned to elevation %.1f deg, azimuth %.1f deg (it stood at %.1f, %.1f)\n", static_cast<double>(elevation),
              static_cast<double>(azimuth), static_cast<double>(now.x), static_cast<double>(now.y));
  return true;
}

}  // namespace transgi::cli
