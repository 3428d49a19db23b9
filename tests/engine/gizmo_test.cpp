// Gizmo and picking maths: known answers, including edge-on handles and
// snapping, and drags that apply a delta to the start transform.
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "engine/editor/gizmo_math.h"
#include "engine/editor/undo_stack.h"

using namespace engine;
using namespace engine::editor;

namespace {

constexpr float kPi = 3.14159265358979f;

void expect_vec3(const glm::vec3& got, const glm::vec3& want, float tol) {
  EXPECT_NEAR(got.x, want.x, tol) << "x";
  EXPECT_NEAR(got.y, want.y, tol) << "y";
  EXPECT_NEAR(got.z, want.z, tol) << "z";
}

TEST(GizmoMath, ClosestPointOnAnAxisToASkewRay) {
  // The X axis through the origin; a ray along -Z passing through (2, 3, 5).
  const PickRay ray{{2, 3, 5}, {0, 0, -1}};
  const auto s = closest_on_axis(ray, {0, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(*s, 2.0f, 1e-6f);
  // A slanted ray: the closest point is where the common perpendicular meets the axis.
  const PickRay slanted{{0, 1, 4}, glm::normalize(glm::vec3(1, 0, -1))};
  const auto s2 = closest_on_axis(slanted, {0, 0, 0}, {1, 0, 0});
  ASSERT_TRUE(s2.has_value());
  EXPECT_NEAR(*s2, 4.0f, 1e-5f) << "the ray crosses x = 4 at z = 0, one unit above the axis";
}

TEST(GizmoMath, PastTheVanishingPointNothingIsRead) {
  // The axis runs away from a camera at the origin looking down -Z, offset
  // one unit in x. A ray aimed across the axis's vanishing direction meets
  // it only behind the camera.
  const glm::vec3 axis = glm::normalize(glm::vec3(0.2f, 0, -1));
  const PickRay ahead{{0, 0, 0}, glm::normalize(glm::vec3(1.5f, 0, -1))};
  EXPECT_TRUE(closest_on_axis(ahead, {1, 0, -2}, axis).has_value());
  const PickRay past{{0, 0, 0}, glm::normalize(glm::vec3(0.1f, 0, -1))};
  EXPECT_FALSE(closest_on_axis(past, {1, 0, -2}, axis).has_value());
}

TEST(GizmoMath, AnAxisAlongTheRayCannotBeDragged) {
  const PickRay ray{{0, 0, 5}, {0, 0, -1}};
  EXPECT_FALSE(closest_on_axis(ray, {0, 0, 0}, {0, 0, 1}).has_value());
  EXPECT_TRUE(edge_on({0, 0, -1}, {0, 0, 1}));
  EXPECT_TRUE(edge_on({0.1f, 0, -1}, {0, 0, 1})) << "5.7 degrees off the view is still too short on screen";
  EXPECT_FALSE(edge_on({0, 0, -1}, {1, 0, 0}));
  EXPECT_FALSE(edge_on({0.5f, 0, -1}, {0, 0, 1})) << "27 degrees off the view can be dragged";
  // Planes: the XY plane (normal Z) is edge-on when looked at along X.
  EXPECT_TRUE(edge_on({1, 0, 0}, {0, 0, 1}, true));
  EXPECT_FALSE(edge_on({0, 0, -1}, {0, 0, 1}, true));
}

TEST(GizmoMath, RayPlaneHit) {
  const PickRay ray{{1, 5, 2}, {0, -1, 0}};
  const auto t = ray_plane(ray, {0, 1, 0}, {0, 1, 0});
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 4.0f, 1e-6f);
  EXPECT_FALSE(ray_plane(ray, {0, 6, 0}, {0, 1, 0}).has_value()) << "behind the ray";
  EXPECT_FALSE(ray_plane({{0, 0, 0}, {1, 0, 0}}, {0, 1, 0}, {0, 1, 0}).has_value()) << "parallel";
}

TEST(GizmoMath, RingAngleByAtan2) {
  const glm::vec3 axis(0, 0, 1), ref = ring_reference(axis), c(1, 1, 1);
  expect_vec3(ref, {1, 0, 0}, 1e-6f);
  EXPECT_NEAR(ring_angle(c + glm::vec3(2, 0, 0), c, axis, ref), 0.0f, 1e-6f);
  EXPECT_NEAR(ring_angle(c + glm::vec3(0, 3, 0), c, axis, ref), kPi / 2, 1e-6f);
  EXPECT_NEAR(ring_angle(c + glm::vec3(-1, -1, 0.5f), c, axis, ref), -3 * kPi / 4, 1e-6f) << "height along the axis is ignored";
  EXPECT_NEAR(wrap_angle(3 * kPi / 2), -kPi / 2, 1e-5f);
  EXPECT_NEAR(wrap_angle(-3 * kPi / 2), kPi / 2, 1e-5f);
  for (glm::vec3 a : {glm::vec3(0, 1, 0), glm::vec3(1, 0, 0), glm::normalize(glm::vec3(1, 2, 3))}) {
    const glm::vec3 r = ring_reference(a);
    EXPECT_NEAR(glm::dot(r, a), 0.0f, 1e-6f);
    EXPECT_NEAR(glm::length(r), 1.0f, 1e-6f);
  }
}

TEST(GizmoMath, ConstantScreenSize) {
  // 90 degree fov over 1000 pixels: at distance d the view is 2d tall, so 100 pixels are 0.2 d.
  EXPECT_NEAR(world_size_for_pixels(100, 1, kPi / 2, 1000), 0.2f, 1e-6f);
  EXPECT_NEAR(world_size_for_pixels(100, 7, kPi / 2, 1000), 1.4f, 1e-5f);
}

TEST(GizmoMath, SnapRoundsToTheStep) {
  EXPECT_EQ(snap(0.37f, 0.25f), 0.25f);
  EXPECT_EQ(snap(0.38f, 0.25f), 0.5f);
  EXPECT_EQ(snap(-0.38f, 0.25f), -0.5f);
  EXPECT_EQ(snap(0.37f, 0.0f), 0.37f) << "no snap without Ctrl";
}

TEST(GizmoDrag, TranslateIsStartPlusDeltaInTheParentFrame) {
  transform::Transform start = transform::Transform::from_translation({1, 2, 3});
  transform::Similarity parent;
  parent.rotation = glm::angleAxis(kPi / 2, glm::vec3(0, 1, 0));  // parent's +X is world -Z
  parent.scale = 2.0f;
  const transform::Transform t = translated(start, parent, {0, 0, -4});
  expect_vec3(t.translation, {3, 2, 3}, 1e-5f);  // 4 world units = 2 parent units along the parent's +X
  // Many small moves of the same total give the same answer: no accumulation.
  transform::Transform inc = start;
  for (int i = 1; i <= 1000; ++i) inc = translated(start, parent, {0, 0, -4.0f * static_cast<float>(i) / 1000});
  EXPECT_EQ(inc.translation, t.translation);
  // Ctrl snaps each local component.
  expect_vec3(translated(start, {}, {0.26f, 0.0f, -0.9f}, 0.5f).translation, {1.5f, 2.0f, 2.0f}, 1e-6f);
}

TEST(GizmoDrag, RotateAboutAWorldAxisWithSnapping) {
  transform::Transform start;
  start.rotation = glm::angleAxis(0.3f, glm::vec3(1, 0, 0));
  const transform::Transform t = rotated(start, {}, {0, 1, 0}, kPi / 2, start.translation);
  // The object's local +Z, first tilted by the start rotation, then turned about world Y.
  const glm::vec3 want = glm::angleAxis(kPi / 2, glm::vec3(0, 1, 0)) * (start.rotation * glm::vec3(0, 0, 1));
  expect_vec3(t.rotation * glm::vec3(0, 0, 1), want, 1e-6f);
  // 15-degree snapping: 50 degrees becomes 45.
  const float step = kPi / 12;
  const transform::Transform s = rotated(transform::Transform{}, {}, {0, 0, 1}, 50.0f * kPi / 180, glm::vec3(0.0f), step);
  expect_vec3(s.rotation * glm::vec3(1, 0, 0), {std::cos(kPi / 4), std::sin(kPi / 4), 0}, 1e-6f);
  // Under a rotated parent the world axis is honoured.
  transform::Similarity parent;
  parent.rotation = glm::angleAxis(kPi / 2, glm::vec3(1, 0, 0));
  const transform::Transform c = rotated(transform::Transform{}, parent, {0, 1, 0}, kPi / 2, glm::vec3(0.0f));
  const glm::vec3 world_x = parent.rotation * (c.rotation * glm::vec3(1, 0, 0));
  expect_vec3(world_x, {0, 0, -1}, 1e-6f);
}

TEST(GizmoDrag, RotateAboutAPivotKeepsThePivotInPlace) {
  // An object at the origin turned a quarter about +Y through (1, 0, 0):
  // its origin swings from (0, 0, 0) to (1, 0, 1).
  const transform::Transform t = rotated(transform::Transform{}, {}, {0, 1, 0}, kPi / 2, {1, 0, 0});
  expect_vec3(t.translation, {1, 0, 1}, 1e-6f);
  // Under a scaled, moved parent the world pivot still stays where it was.
  transform::Similarity parent;
  parent.translation = {2, 0, 0};
  parent.rotation = glm::angleAxis(0.7f, glm::vec3(0, 0, 1));
  parent.scale = 2.0f;
  transform::Transform start = transform::Transform::from_translation({0.5f, 0.25f, -1});
  const glm::vec3 pivot(3, 1, -1.5f);
  const transform::Transform r = rotated(start, parent, glm::normalize(glm::vec3(1, 1, 0)), 1.1f, pivot);
  // The point of the object that sat on the pivot is still on it.
  const glm::vec3 local_before = (parent * start).inverse().apply_point(pivot);
  expect_vec3((parent * r).apply_point(local_before), pivot, 1e-5f);
}

TEST(GizmoPicking, ProjectionAndPickRayAgree) {
  transform::Similarity cam;
  cam.translation = {0, 1, 5};
  cam.rotation = glm::angleAxis(0.2f, glm::vec3(0, 1, 0));
  const float fov = 0.9f, aspect = 16.0f / 9.0f;
  const glm::vec2 viewport(640, 360);
  const glm::mat4 view = glm::inverse(cam.matrix());
  const glm::mat4 proj = glm::perspective(fov, aspect, 0.01f, 100.0f);
  const glm::vec3 p(0.3f, 0.7f, -1.0f);
  const auto px = project_to_pixels(proj * view, viewport, p);
  ASSERT_TRUE(px.has_value());
  const PickRay r = pick_ray(cam, fov, aspect, viewport, *px);
  const glm::vec3 to_p = glm::normalize(p - r.origin);
  EXPECT_NEAR(glm::dot(to_p, r.direction), 1.0f, 1e-6f);
  EXPECT_FALSE(project_to_pixels(proj * view, viewport, cam.translation + cam.rotation * glm::vec3(0, 0, 3)).has_value())
      << "a point behind the camera has no pixel";
  EXPECT_NEAR(distance_to_segment({5, 5}, {0, 0}, {10, 0}), 5.0f, 1e-6f);
  EXPECT_NEAR(distance_to_segment({-3, 4}, {0, 0}, {10, 0}), 5.0f, 1e-6f);
}

TEST(UndoStack, UndoAndRedoPerDrag) {
  ecs::World world;
  const ecs::Entity e = world.spawn();
  world.emplace<transform::Transform>(e, transform::Transform::from_translation({0, 0, 0}));
  UndoStack undo;
  const auto a = transform::Transform::from_translation({1, 0, 0});
  const auto b = transform::Transform::from_translation({1, 2, 0});
  world.get_mut<transform::Transform>(e) = a;
  undo.push({e, transform::Transform{}, a});
  world.get_mut<transform::Transform>(e) = b;
  undo.push({e, a, b});
  undo.push({e, b, b});  // a click without a move
  EXPECT_EQ(undo.undo_count(), 2u);
  ASSERT_TRUE(undo.undo(world));
  EXPECT_EQ(world.get<transform::Transform>(e).translation, a.translation);
  ASSERT_TRUE(undo.undo(world));
  EXPECT_EQ(world.get<transform::Transform>(e).translation, glm::vec3(0.0f));
  EXPECT_FALSE(undo.undo(world));
  ASSERT_TRUE(undo.redo(world));
  EXPECT_EQ(world.get<transform::Transform>(e).translation, a.translation);
  undo.push({e, a, b});  // a new edit drops the redo history
  EXPECT_EQ(undo.redo_count(), 0u);
  world.despawn(e);
  EXPECT_FALSE(undo.undo(world)) << "edits of a despawned entity are skipped";
}

}  // namespace
