// The time-of-day sun (issue 16): angles to direction and back, and a
// directional light turned by set_sun shines from where the angles say.
#include <gtest/gtest.h>

#include "engine/scene/components.h"
#include "engine/scene/sun.h"
#include "engine/transform/transform.h"

using namespace engine;

TEST(Sun, AnglesRoundTripAndTheLightShinesAwayFromTheSun) {
  for (float e : {-30.0f, 0.0f, 17.0f, 45.0f, 89.9f, 90.0f})
    for (float a : {-170.0f, -90.0f, 0.0f, 30.0f, 135.0f}) {
      const glm::vec3 d = scene::direction_to_sun(e, a);
      EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
      EXPECT_NEAR(d.y, std::sin(glm::radians(e)), 1e-6f) << "elevation " << e;
      const glm::vec2 back = scene::sun_angles(d);
      EXPECT_NEAR(back.x, e, 1e-3f);
      if (e < 89.0f) {
        EXPECT_NEAR(back.y, a, 1e-3f) << "elevation " << e << " azimuth " << a;
      }
      // A glTF directional light shines along its -z.
      const glm::vec3 travel = scene::sun_rotation(e, a) * glm::vec3(0, 0, -1);
      EXPECT_NEAR(glm::dot(travel, -d), 1.0f, 1e-5f) << "elevation " << e << " azimuth " << a;
    }
  // Known answers: noon sun straight up, a sunset in the +x direction.
  EXPECT_NEAR(scene::direction_to_sun(90, 0).y, 1.0f, 1e-6f);
  const glm::vec3 west = scene::direction_to_sun(0, 90);
  EXPECT_NEAR(west.x, 1.0f, 1e-6f);
  EXPECT_NEAR(west.z, 0.0f, 1e-6f);
}

TEST(Sun, SetSunTurnsTheFirstDirectionalLightAndRefusesBadAngles) {
  ecs::World w;
  const ecs::Entity lamp = w.spawn();
  w.emplace<transform::Transform>(lamp);
  w.emplace<scene::PunctualLight>(lamp, scene::PunctualLight{.type = scene::PunctualLight::Type::Point});
  EXPECT_THROW(scene::set_sun(w, 30, 0), std::runtime_error) << "no directional light";
  const ecs::Entity sun = w.spawn();
  w.emplace<transform::Transform>(sun, transform::Transform::from_translation({1, 2, 3}));
  w.emplace<scene::PunctualLight>(sun, scene::PunctualLight{.type = scene::PunctualLight::Type::Directional});
  scene::set_sun(w, 25, -60);
  const transform::Transform& t = w.get<transform::Transform>(sun);
  EXPECT_EQ(t.translation, glm::vec3(1, 2, 3));
  EXPECT_NEAR(glm::dot(t.rotation * glm::vec3(0, 0, -1), -scene::direction_to_sun(25, -60)), 1.0f, 1e-5f);
  EXPECT_EQ(w.get<transform::Transform>(lamp).rotation, glm::quat(1, 0, 0, 0)) << "the point light is not the sun";
  EXPECT_THROW(scene::set_sun(w, 95, 0), std::runtime_error);
  EXPECT_THROW(scene::set_sun(w, std::nanf(""), 0), std::runtime_error);
}
