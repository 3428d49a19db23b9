#pragma once
// The maths of translate and rotate gizmos, as pure functions (ImGuizmo is
// not packaged in Debian, and these few formulas are easier to test than a
// widget). A drag is always "start transform + delta since the press", so
// error never accumulates over mouse-move events; deltas are measured in
// world space and carried into the parent's space.
#include <array>
#include <optional>

#include <glm/glm.hpp>

#include "engine/transform/transform.h"

namespace engine::editor {

struct PickRay {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // unit length
};

// Parameter s of the point (point + s * axis) on the axis line that is
// closest to the ray (axis unit length). Empty when the ray runs parallel
// to the axis, where no drag along it can be read, and when that point lies
// behind the ray's origin (the cursor went past the axis's vanishing point).
std::optional<float> closest_on_axis(const PickRay& ray, const glm::vec3& point, const glm::vec3& axis);

// Distance t along the ray to the plane through `point` with `normal`, or
// empty when the ray is parallel to the plane or the plane is behind it.
std::optional<float> ray_plane(const PickRay& ray, const glm::vec3& point, const glm::vec3& normal);

// Angle (radians, in (-pi, pi]) of `p` around `axis` through `centre`,
// measured from `reference` (perpendicular to axis) by atan2, counter-
// clockwise seen from where the axis points.
float ring_angle(const glm::vec3& p, const glm::vec3& centre, const glm::vec3& axis, const glm::vec3& reference);

// A unit vector perpendicular to `axis`: the zero angle of its ring.
glm::vec3 ring_reference(const glm::vec3& axis);

// World size that covers `pixels` on screen at `distance` from a camera with
// vertical field of view fov_y over a viewport `viewport_height` pixels tall:
// the gizmo's scale, so it keeps one screen size at every distance.
float world_size_for_pixels(float pixels, float distance, float fov_y, float viewport_height);

// True when an axis points (nearly) along the view direction: its handle is
// too short on screen to drag and is hidden. For a plane handle pass its
// normal with plane = true: the plane is edge-on when the normal is
// (nearly) perpendicular to the view.
bool edge_on(const glm::vec3& view_direction, const glm::vec3& axis_or_normal, bool plane = false, float cos_limit = 0.985f);

// Rounds v to the nearest multiple of step (step <= 0: v unchanged).
float snap(float v, float step);
// Wraps an angle difference into (-pi, pi].
float wrap_angle(float radians);

// The drags. `parent` is the parent's world transform (identity for a root).
// Translation: start + world_delta carried into the parent's frame, each
// component snapped when snap_step > 0 (Ctrl held).
transform::Transform translated(const transform::Transform& start, const transform::Similarity& parent,
                                const glm::vec3& world_delta, float snap_step = 0.0f);
// Rotation about a world axis through `world_pivot` by `radians` (snapped
// to snap_step if > 0), applied after the start rotation; the pivot stays
// put. The pivot is the gizmo's: the object's origin, or the centre of its
// bounds for meshes whose vertices were exported in world space.
transform::Transform rotated(const transform::Transform& start, const transform::Similarity& parent,
                             const glm::vec3& world_axis, float radians, const glm::vec3& world_pivot, float snap_step = 0.0f);

// Screen-space helpers for picking a handle: the projection of a world point
// to pixels (y down; empty behind the camera) and the distance in pixels
// from a point to a segment.
std::optional<glm::vec2> project_to_pixels(const glm::mat4& view_projection, const glm::vec2& viewport, const glm::vec3& p);
float distance_to_segment(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b);

// The pick ray through pixel (x, y) (y down) for a camera at `camera` with
// the given vertical fov and aspect, looking down its local -Z.
PickRay pick_ray(const transform::Similarity& camera, float fov_y, float aspect, const glm::vec2& viewport, const glm::vec2& pixel);

}  // namespace engine::editor
