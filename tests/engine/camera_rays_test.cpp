#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

#include "engine/render/camera_rays.h"

using namespace engine;

// project() is generate()'s inverse: the film point a ray was generated
// through comes back from any point along that ray, for a turned camera and
// a non-square film; points behind the camera have no film point.
TEST(CameraRays, ProjectInvertsGenerate) {
  scene::Camera camera;
  camera.yfov_radians = 0.9f;
  transform::Similarity to_world;
  to_world.translation = glm::vec3(1.0f, 2.0f, -3.0f);
  to_world.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f)));
  const render::CameraRays rays(camera, to_world, 64, 36);
  for (const glm::vec2 film : {glm::vec2(0.5f, 0.5f), glm::vec2(32.0f, 18.0f), glm::vec2(63.5f, 2.25f), glm::vec2(10.0f, 35.0f)})
    for (const float t : {0.1f, 2.0f, 75.0f}) {
      const rt::Ray r = rays.generate(film);
      const std::optional<glm::vec2> back = rays.project(r.origin + t * r.direction);
      ASSERT_TRUE(back.has_value()) << "film (" << film.x << ", " << film.y << ") at t = " << t;
      EXPECT_NEAR(back->x, film.x, 1e-3f * std::max(1.0f, t)) << "t = " << t;
      EXPECT_NEAR(back->y, film.y, 1e-3f * std::max(1.0f, t)) << "t = " << t;
    }
  const rt::Ray centre = rays.generate({32.0f, 18.0f});
  EXPECT_FALSE(rays.project(centre.origin - 2.0f * centre.direction).has_value()) << "a point behind the camera";
}
