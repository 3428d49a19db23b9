#pragma once
// The sun as a directional light that a time-of-day control turns. A glTF
// directional light shines along its node's local -z; here its direction is
// given by where the sun stands in the sky.
#include <optional>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/ecs/world.h"

namespace engine::scene {

// Unit vector from the scene towards a sun at `elevation` above the horizon
// and `azimuth` from +z towards +x (degrees): (cos e sin a, sin e, cos e cos a).
glm::vec3 direction_to_sun(float elevation_deg, float azimuth_deg);
// The inverse: elevation and azimuth (degrees) of a unit direction to the sun.
glm::vec2 sun_angles(const glm::vec3& to_sun);
// The rotation that makes a directional light shine from there (its -z away from the sun).
glm::quat sun_rotation(float elevation_deg, float azimuth_deg);

// The first directional PunctualLight with a Transform, if any.
std::optional<ecs::Entity> find_sun(ecs::World& world);
// Turns that light to stand at (elevation, azimuth), keeping its position;
// throws std::runtime_error if the scene has no directional light, or an
// angle is not finite or elevation lies outside [-90, 90].
void set_sun(ecs::World& world, float elevation_deg, float azimuth_deg);

}  // namespace engine::scene
