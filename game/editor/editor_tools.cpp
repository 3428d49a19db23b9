#include "editor/editor_tools.h"

#include <cmath>
#include <optional>
#include <vector>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "engine/editor/gizmo_math.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"

namespace game {

namespace {

using engine::ecs::Entity;
using engine::ecs::World;
namespace ed = engine::editor;
namespace tf = engine::transform;

glm::mat4 view_projection(const EditorView& v) {
  return glm::perspective(v.fov_y, v.aspect, 0.01f, 1000.0f) * glm::inverse(v.camera.matrix());
}

glm::vec3 axis_of(GizmoHandle h) {
  switch (h) {
    case GizmoHandle::X: case GizmoHandle::RX: return {1, 0, 0};
    case GizmoHandle::Y: case GizmoHandle::RY: return {0, 1, 0};
    case GizmoHandle::Z: case GizmoHandle::RZ: return {0, 0, 1};
    case GizmoHandle::XY: return {1, 0, 0};
    case GizmoHandle::YZ: return {0, 1, 0};
    case GizmoHandle::ZX: return {0, 0, 1};
    case GizmoHandle::None: break;
  }
  return {0, 0, 0};
}

bool is_ring(GizmoHandle h) { return h == GizmoHandle::RX || h == GizmoHandle::RY || h == GizmoHandle::RZ; }
bool is_plane(GizmoHandle h) { return h == GizmoHandle::XY || h == GizmoHandle::YZ || h == GizmoHandle::ZX; }
glm::vec3 second_axis_of(GizmoHandle h) {
  switch (h) {
    case GizmoHandle::XY: return {0, 1, 0};
    case GizmoHandle::YZ: return {0, 0, 1};
    case GizmoHandle::ZX: return {1, 0, 0};
    default: return {0, 0, 0};
  }
}
constexpr float kPlaneFrom = 0.2f, kPlaneTo = 0.45f;  // the square's extent, in gizmo sizes

tf::Similarity parent_world(const World& world, Entity e) {
  if (const auto* p = world.try_get<tf::Parent>(e))
    if (world.alive(p->entity))
      if (const auto* w = world.try_get<tf::WorldTransform>(p->entity)) return *w;
  return {};
}

// A ring seen this close to edge-on (|cos| of its axis and the view) is a
// thin ellipse or a line: the pick ray meets its plane at a grazing angle,
// so it is picked and turned in screen space instead.
constexpr float kRingEdgeOnCos = 0.3f;
bool ring_near_edge_on(const HandleGeometry& g, const EditorView& view) {
  return std::abs(glm::dot(glm::normalize(g.pivot - view.camera.translation), g.axis)) < kRingEdgeOnCos;
}

// The ring's points, `count` of them, by angle from ed::ring_reference.
constexpr int kRingSamples = 64;
glm::vec3 ring_sample(const HandleGeometry& g, float angle) {
  const glm::vec3 ref = ed::ring_reference(g.axis), other = glm::cross(g.axis, ref);
  return g.pivot + g.size * (std::cos(angle) * ref + std::sin(angle) * other);
}

struct RingOnScreen {
  float pixels = INFINITY;  // from the cursor to the ring as drawn
  float angle = 0.0f;       // the nearest sample's angle
};
// The cursor's distance to the ring's projected outline, and where on it.
RingOnScreen ring_on_screen(const HandleGeometry& g, const glm::mat4& vp, const glm::vec2& viewport, const glm::vec2& mouse) {
  RingOnScreen best;
  std::optional<glm::vec2> prev = ed::project_to_pixels(vp, viewport, ring_sample(g, 0.0f));
  for (int k = 1; k <= kRingSamples; ++k) {
    const float a = 2.0f * glm::pi<float>() * static_cast<float>(k) / kRingSamples;
    const auto cur = ed::project_to_pixels(vp, viewport, ring_sample(g, a));
    if (prev && cur) {
      const float d = ed::distance_to_segment(mouse, *prev, *cur);
      if (d < best.pixels) {
        best.pixels = d;
        // The nearer end's angle.
        best.angle = glm::length(mouse - *prev) < glm::length(mouse - *cur) ? a - 2.0f * glm::pi<float>() / kRingSamples : a;
      }
    }
    prev = cur;
  }
  return best;
}

// The ring's point under the cursor, if the pick ray meets the ring's plane.
std::optional<glm::vec3> ring_point(const ed::PickRay& ray, const HandleGeometry& g) {
  const auto t = ed::ray_plane(ray, g.pivot, g.axis);
  if (!t) return std::nullopt;
  return ray.origin + *t * ray.direction;
}

GizmoHandle hovered_handle(const World& world, const EditorState& s, const EditorView& view, const glm::vec2& mouse) {
  const glm::mat4 vp = view_projection(view);
  const ed::PickRay ray = ed::pick_ray(view.camera, view.fov_y, view.aspect, view.viewport, mouse);
  const auto handles = s.mode == GizmoMode::Translate
                           ? std::vector<GizmoHandle>{GizmoHandle::X, GizmoHandle::Y, GizmoHandle::Z,
                                                      GizmoHandle::XY, GizmoHandle::YZ, GizmoHandle::ZX}
                           : std::vector<GizmoHandle>{GizmoHandle::RX, GizmoHandle::RY, GizmoHandle::RZ};
  GizmoHandle best = GizmoHandle::None, plane = GizmoHandle::None;
  float best_pixels = s.pick_pixels;
  for (GizmoHandle h : handles) {
    const HandleGeometry g = handle_geometry(world, s, view, h);
    if (!g.visible) continue;
    if (is_plane(h)) {  // a square under the cursor, if no axis is within reach (below)
      const glm::vec3 n = glm::cross(g.axis, g.axis2);
      if (const auto t = ed::ray_plane(ray, g.pivot, n); t && plane == GizmoHandle::None) {
        const glm::vec3 d = (ray.origin + *t * ray.direction - g.pivot) / g.size;
        const float a = glm::dot(d, g.axis), b = glm::dot(d, g.axis2);
        if (a >= kPlaneFrom && a <= kPlaneTo && b >= kPlaneFrom && b <= kPlaneTo) plane = h;
      }
      continue;
    }
    float pixels = INFINITY;
    if (!is_ring(h)) {
      const auto a = ed::project_to_pixels(vp, view.viewport, g.pivot + 0.15f * g.size * g.axis);
      const auto b = ed::project_to_pixels(vp, view.viewport, g.pivot + g.size * g.axis);
      if (a && b) pixels = ed::distance_to_segment(mouse, *a, *b);
    } else {
      // As drawn on screen, so a ring seen edge-on (a line) is picked too.
      pixels = ring_on_screen(g, vp, view.viewport, mouse).pixels;
    }
    if (pixels < best_pixels) {
      best_pixels = pixels;
      best = h;
    }
  }
  return best != GizmoHandle::None ? best : plane;  // an axis line is thin: it wins where it is
}

}  // namespace

GizmoHandle parse_handle(const std::string& name) {
  if (name == "x") return GizmoHandle::X;
  if (name == "y") return GizmoHandle::Y;
  if (name == "z") return GizmoHandle::Z;
  if (name == "xy") return GizmoHandle::XY;
  if (name == "yz") return GizmoHandle::YZ;
  if (name == "zx") return GizmoHandle::ZX;
  if (name == "rx") return GizmoHandle::RX;
  if (name == "ry") return GizmoHandle::RY;
  if (name == "rz") return GizmoHandle::RZ;
  return GizmoHandle::None;
}

glm::vec3 gizmo_pivot(const World& world, Entity e) {
  const glm::vec3 origin = world.get<tf::WorldTransform>(e).translation;
  const auto* rt = world.try_resource<engine::rt::RtScene>();
  const engine::rt::InstanceRecord* inst = rt ? rt->instance_of(e) : nullptr;
  if (!inst || !inst->active) return origin;
  const engine::rt::WorldBounds& b = inst->bounds;
  const bool inside = glm::all(glm::greaterThanEqual(origin, b.min)) && glm::all(glm::lessThanEqual(origin, b.max));
  return inside ? origin : 0.5f * (b.min + b.max);
}

HandleGeometry handle_geometry(const World& world, const EditorState& s, const EditorView& view, GizmoHandle h) {
  HandleGeometry g;
  if (h == GizmoHandle::None || s.selected.is_null() || !world.alive(s.selected)) return g;
  const auto* w = world.try_get<tf::WorldTransform>(s.selected);
  if (!w) return g;
  g.pivot = s.active != GizmoHandle::None ? s.pivot : gizmo_pivot(world, s.selected);
  g.axis = axis_of(h);
  g.axis2 = second_axis_of(h);
  const float distance = glm::length(g.pivot - view.camera.translation);
  g.size = ed::world_size_for_pixels(s.gizmo_fraction * view.viewport.y, std::max(distance, 1e-3f), view.fov_y, view.viewport.y);
  const glm::vec3 view_dir = glm::normalize(g.pivot - view.camera.translation);
  // Axes and squares seen end- or edge-on cannot be dragged and hide; a
  // ring edge-on is a line that turns in screen space, so it always shows.
  g.visible = is_plane(h) ? !ed::edge_on(view_dir, glm::cross(g.axis, g.axis2), true) : is_ring(h) || !ed::edge_on(view_dir, g.axis);
  return g;
}

std::optional<glm::vec2> handle_grab_pixel(const World& world, const EditorState& s, const EditorView& view, GizmoHandle h) {
  const HandleGeometry g = handle_geometry(world, s, view, h);
  if (!g.visible) return std::nullopt;
  glm::vec3 p;
  if (is_plane(h)) {
    p = g.pivot + 0.5f * (kPlaneFrom + kPlaneTo) * g.size * (g.axis + g.axis2);
  } else if (!is_ring(h)) {
    p = g.pivot + 0.8f * g.size * g.axis;
  } else {
    const glm::vec3 to_camera = glm::normalize(view.camera.translation - g.pivot);
    const glm::vec3 across = glm::cross(g.axis, to_camera);
    if (glm::length(across) < 1e-4f) {
      p = ring_sample(g, 0.0f);  // seen face-on: any point of the circle
    } else if (ring_near_edge_on(g, view)) {
      // Seen as a line through the pivot: halfway out along it, 30 degrees
      // from the point nearest the camera, clear of the other rings.
      glm::vec3 toward = to_camera - glm::dot(to_camera, g.axis) * g.axis;
      toward = glm::length(toward) > 1e-4f ? glm::normalize(toward) : glm::normalize(glm::cross(across, g.axis));
      p = g.pivot + g.size * (0.5f * glm::normalize(across) + 0.8660254f * toward);
    } else {  // the ring's point facing most across the view
      p = g.pivot + g.size * glm::normalize(across);
    }
  }
  return ed::project_to_pixels(view_projection(view), view.viewport, p);
}

Entity pick_entity(World& world, const EditorView& view, const glm::vec2& pixel, float pick_pixels) {
  const ed::PickRay ray = ed::pick_ray(view.camera, view.fov_y, view.aspect, view.viewport, pixel);
  Entity best;
  float best_t = INFINITY;
  if (const auto* rt = world.try_resource<engine::rt::RtScene>()) {
    engine::rt::Ray r;
    r.origin = ray.origin;
    r.direction = ray.direction;
    engine::rt::Hit hit;
    if (rt->intersect(r, hit) && world.alive(hit.entity)) {
      best = hit.entity;
      best_t = hit.t;
    }
  }
  const glm::mat4 vp = view_projection(view);
  world.view<const engine::scene::PunctualLight, const tf::WorldTransform>().each(
      [&](Entity e, const engine::scene::PunctualLight&, const tf::WorldTransform& w) {
        const auto px = ed::project_to_pixels(vp, view.viewport, w.translation);
        const float t = glm::length(w.translation - ray.origin);
        if (px && glm::length(*px - pixel) < pick_pixels * 1.5f && t < best_t) {
          best = e;
          best_t = t;
        }
      });
  return best;
}

void update_editor(World& world, EditorState& s, const engine::input::InputState& in, const EditorView& view) {
  if (!s.selected.is_null() && !world.alive(s.selected)) {  // despawned (by a script, say): drop it and any drag
    s.selected = {};
    s.active = s.hovered = GizmoHandle::None;
  }
  const bool ctrl = in.is_down("ctrl");
  if (ctrl && in.was_pressed("Z")) s.undo.undo(world);
  if (ctrl && in.was_pressed("Y")) s.undo.redo(world);
  const glm::vec2 mouse = in.mouse;
  const ed::PickRay ray = ed::pick_ray(view.camera, view.fov_y, view.aspect, view.viewport, mouse);

  if (s.active == GizmoHandle::None) {
    s.hovered = s.selected.is_null() ? GizmoHandle::None : hovered_handle(world, s, view, mouse);
    if (!in.was_pressed("mouse_left")) return;
    if (s.hovered == GizmoHandle::None) {
      s.selected = pick_entity(world, view, mouse, s.pick_pixels);
      return;
    }
    const HandleGeometry g = handle_geometry(world, s, view, s.hovered);
    const auto* t = world.try_get<tf::Transform>(s.selected);  // a press alone changes nothing
    if (!t) return;
    if (is_plane(s.hovered)) {
      const auto hit = ed::ray_plane(ray, g.pivot, glm::cross(g.axis, g.axis2));
      if (!hit) return;
      s.start_hit = ray.origin + *hit * ray.direction;
    } else if (!is_ring(s.hovered)) {
      const auto p = ed::closest_on_axis(ray, g.pivot, g.axis);
      if (!p) return;
      s.start_param = *p;
    } else if (ring_near_edge_on(g, view)) {
      // In screen space: the cursor's motion along the ring's tangent where
      // it was grabbed, one radian per ring radius on screen.
      const glm::mat4 vp = view_projection(view);
      const float a = ring_on_screen(g, vp, view.viewport, mouse).angle;
      const glm::vec3 at = ring_sample(g, a), tangent = glm::normalize(glm::cross(g.axis, at - g.pivot));
      const auto p0 = ed::project_to_pixels(vp, view.viewport, at), p1 = ed::project_to_pixels(vp, view.viewport, at + 0.05f * g.size * tangent);
      const auto centre = ed::project_to_pixels(vp, view.viewport, g.pivot), rim = ed::project_to_pixels(vp, view.viewport, g.pivot + g.size * glm::normalize(glm::cross(g.axis, view.camera.translation - g.pivot)));
      if (!p0 || !p1 || !centre || !rim || glm::length(*p1 - *p0) < 1e-3f) return;
      s.ring_by_screen = true;
      s.grab_mouse = mouse;
      s.screen_tangent = glm::normalize(*p1 - *p0);
      s.pixels_per_radian = std::max(glm::length(*rim - *centre), 1.0f);
      s.angle = 0.0f;
    } else {
      const auto p = ring_point(ray, g);
      if (!p) return;
      s.ring_by_screen = false;
      s.last_angle = ed::ring_angle(*p, g.pivot, g.axis, ed::ring_reference(g.axis));
      s.angle = 0.0f;
    }
    s.active = s.hovered;
    s.start = *t;
    s.parent = parent_world(world, s.selected);
    s.pivot = g.pivot;
    return;
  }

  // Dragging.
  const HandleGeometry g = handle_geometry(world, s, view, s.active);
  auto* t = world.alive(s.selected) ? world.try_get_mut<tf::Transform>(s.selected) : nullptr;
  if (t) {
    if (is_plane(s.active)) {
      const glm::vec3 n = glm::cross(g.axis, g.axis2);
      if (const auto hit = ed::ray_plane(ray, g.pivot, n)) {
        glm::vec3 delta = ray.origin + *hit * ray.direction - s.start_hit;
        delta -= glm::dot(delta, n) * n;  // exactly in the plane: rounding must not lift the object
        *t = ed::translated(s.start, s.parent, delta, ctrl ? s.translate_snap : 0.0f);
      }
    } else if (!is_ring(s.active)) {
      if (const auto p = ed::closest_on_axis(ray, g.pivot, g.axis))
        *t = ed::translated(s.start, s.parent, (*p - s.start_param) * g.axis, ctrl ? s.translate_snap : 0.0f);
    } else if (s.ring_by_screen) {
      s.angle = glm::dot(mouse - s.grab_mouse, s.screen_tangent) / s.pixels_per_radian;
      *t = ed::rotated(s.start, s.parent, g.axis, s.angle, s.pivot, ctrl ? glm::radians(s.rotate_snap_degrees) : 0.0f);
    } else if (const auto p = ring_point(ray, g)) {
      const float a = ed::ring_angle(*p, g.pivot, g.axis, ed::ring_reference(g.axis));
      s.angle += ed::wrap_angle(a - s.last_angle);  // unwrapped total since the press
      s.last_angle = a;
      *t = ed::rotated(s.start, s.parent, g.axis, s.angle, s.pivot, ctrl ? glm::radians(s.rotate_snap_degrees) : 0.0f);
    }
  }
  if (!in.is_down("mouse_left")) {
    if (t) s.undo.push({s.selected, s.start, *t});
    s.active = GizmoHandle::None;
    ++s.drags;
  }
}

}  // namespace game
