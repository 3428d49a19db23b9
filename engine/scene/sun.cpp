#include "engine/scene/sun.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/scene/components.h"
#include "engine/transform/transform.h"

namespace engine::scene {

glm::vec3 direction_to_sun(float elevation_deg, float azimuth_deg) {
  const float e = glm::radians(elevation_deg), a = glm::radians(azimuth_deg);
  return {std::cos(e) * std::sin(a), std::sin(e), std::cos(e) * std::cos(a)};
}

glm::vec2 sun_angles(const glm::vec3& d) {
  return {glm::degrees(std::asin(glm::clamp(d.y, -1.0f, 1.0f))), glm::degrees(std::atan2(d.x, d.z))};
}

glm::quat sun_rotation(float elevation_deg, float azimuth_deg) {
  const glm::vec3 travel = -direction_to_sun(elevation_deg, azimuth_deg);
  // quatLookAtRH points -z along `travel`; any up not parallel to it will do.
  const glm::vec3 up = std::abs(travel.y) > 0.999f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  return glm::quatLookAtRH(travel, up);
}

std::optional<ecs::Entity> find_sun(ecs::World& world) {
  std::optional<ecs::Entity> sun;
  world.view<const PunctualLight, const transform::Transform>().each(
      [&](ecs::Entity e, const PunctualLight& l, const transform::Transform&) {
        if (!sun && l.type == PunctualLight::Type::Directional) sun = e;
      });
  return sun;
}

void set_sun(ecs::World& world, float elevation_deg, float azimuth_deg) {
  if (!std::isfinite(elevation_deg) || elevation_deg < -90.0f || elevation_deg > 90.0f)
    throw std::runtime_error("sun elevation must lie in [-90, 90] degrees, got " + std::to_string(elevation_deg));
  if (!std::isfinite(azimuth_deg)) throw std::runtime_error("sun azimuth must be a finite number of degrees");
  const std::optional<ecs::Entity> sun = find_sun(world);
  if (!sun) throw std::runtime_error("the scene has no directional light to turn (KHR_lights_punctual type 'directional')");
  world.get_mut<transform::Transform>(*sun).rotation = sun_rotation(elevation_deg, azimuth_deg);
}

}  // namespace engine::scene
