#include "engine/editor/gizmo_math.h"

#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace engine::editor {

namespace {
constexpr float kPi = 3.14159265358979f;
}

std::optional<float> closest_on_axis(const PickRay& ray, const glm::vec3& point, const glm::vec3& axis) {
  // Lines p(s) = point + s a and r(t) = o + t d; minimise |p(s) - r(t)|.
  const glm::vec3 w = point - ray.origin;
  const float b = glm::dot(axis, ray.direction);
  const float denom = 1.0f - b * b;  // |a| = |d| = 1
  if (denom < 1e-6f) return std::nullopt;
  const float d = glm::dot(axis, w), e = glm::dot(ray.direction, w);
  const float t = (e - b * d) / denom;  // where along the ray
  if (t < 0.0f) return std::nullopt;    // the cursor is past the axis's vanishing point
  return (b * e - d) / denom;
}

std::optional<float> ray_plane(const PickRay& ray, const glm::vec3& point, const glm::vec3& normal) {
  const float denom = glm::dot(normal, ray.direction);
  if (std::abs(denom) < 1e-6f) return std::nullopt;
  const float t = glm::dot(normal, point - ray.origin) / denom;
  if (!(t >= 0.0f) || !std::isfinite(t)) return std::nullopt;
  return t;
}

glm::vec3 ring_reference(const glm::vec3& axis) {
  const glm::vec3 helper = std::abs(axis.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(helper, axis));
}

float ring_angle(const glm::vec3& p, const glm::vec3& centre, const glm::vec3& axis, const glm::vec3& reference) {
  const glm::vec3 v = p - centre;
  const glm::vec3 other = glm::cross(axis, reference);  // reference rotated +90 degrees about axis
  return std::atan2(glm::dot(v, other), glm::dot(v, reference));
}

float world_size_for_pixels(float pixels, float distance, float fov_y, float viewport_height) {
  return pixels * 2.0f * distance * std::tan(0.5f * fov_y) / std::max(viewport_height, 1.0f);
}

bool edge_on(const glm::vec3& view_direction, const glm::vec3& axis_or_normal, bool plane, float cos_limit) {
  const float c = std::abs(glm::dot(glm::normalize(view_direction), glm::normalize(axis_or_normal)));
  return plane ? c < std::sqrt(std::max(0.0f, 1.0f - cos_limit * cos_limit)) : c > cos_limit;
}

float snap(float v, float step) { return step > 0.0f ? std::round(v / step) * step : v; }

float wrap_angle(float radians) {
  float a = std::fmod(radians + kPi, 2.0f * kPi);
  if (a <= 0.0f) a += 2.0f * kPi;
  return a - kPi;
}

transform::Transform translated(const transform::Transform& start, const transform::Similarity& parent,
                                const glm::vec3& world_delta, float snap_step) {
  glm::vec3 local = glm::inverse(parent.rotation) * world_delta / parent.scale;
  if (snap_step > 0.0f) local = {snap(local.x, snap_step), snap(local.y, snap_step), snap(local.z, snap_step)};
  transform::Transform t = start;
  t.translation = start.translation + local;
  return t;
}

transform::Transform rotated(const transform::Transform& start, const transform::Similarity& parent,
                             const glm::vec3& world_axis, float radians, const glm::vec3& world_pivot, float snap_step) {
  const float angle = snap(radians, snap_step);
  const glm::vec3 local_axis = glm::normalize(glm::inverse(parent.rotation) * world_axis);
  const glm::quat turn = glm::angleAxis(angle, local_axis);
  const glm::vec3 pivot = parent.inverse().apply_point(world_pivot);
  transform::Transform t = start;
  t.rotation = glm::normalize(turn * start.rotation);
  t.translation = pivot + turn * (start.translation - pivot);
  return t;
}

std::optional<glm::vec2> project_to_pixels(const glm::mat4& view_projection, const glm::vec2& viewport, const glm::vec3& p) {
  const glm::vec4 c = view_projection * glm::vec4(p, 1.0f);
  if (!(c.w > 1e-6f)) return std::nullopt;
  const glm::vec2 ndc(c.x / c.w, c.y / c.w);
  return glm::vec2((ndc.x * 0.5f + 0.5f) * viewport.x, (0.5f - ndc.y * 0.5f) * viewport.y);
}

float distance_to_segment(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b) {
  const glm::vec2 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float s = len2 > 0.0f ? glm::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + s * ab));
}

PickRay pick_ray(const transform::Similarity& camera, float fov_y, float aspect, const glm::vec2& viewport, const glm::vec2& pixel) {
  const float h = std::tan(0.5f * fov_y);
  const float x = (2.0f * pixel.x / viewport.x - 1.0f) * h * aspect;
  const float y = (1.0f - 2.0f * pixel.y / viewport.y) * h;
  PickRay r;
  r.origin = camera.translation;
  r.direction = glm::normalize(camera.rotation * glm::vec3(x, y, -1.0f));
  return r;
}

}  // namespace engine::editor
