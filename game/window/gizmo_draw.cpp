// The gizmo, drawn on ImGui's foreground list, and the probe visualisation,
// a debug overlay on the background list under the panels.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "engine/editor/gizmo_math.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"
#include "runtime/components.h"
#include "runtime/probe_placement.h"
#include "shading/sh_light.h"
#include "window/editor_ui.h"

namespace game {

namespace {

namespace ed = engine::editor;

ImU32 axis_colour(int axis, bool hot) {
  const ImU32 base[3] = {IM_COL32(230, 70, 70, 255), IM_COL32(90, 210, 90, 255), IM_COL32(80, 130, 240, 255)};
  return hot ? IM_COL32(255, 230, 90, 255) : base[axis];
}

struct Projector {
  glm::mat4 vp;
  EditorView view;
  ViewRect rect;
  const GameOptions* options;
  std::optional<ImVec2> operator()(const glm::vec3& p) const {
    const auto px = ed::project_to_pixels(vp, view.viewport, p);
    if (!px) return std::nullopt;
    const glm::vec2 w = rect.to_window(*px, *options);
    return ImVec2(w.x, w.y);
  }
};

Projector projector(GameSession& s, const ViewRect& rect) {
  const EditorView v = s.view();
  return {glm::perspective(v.fov_y, v.aspect, 0.01f, 1000.0f) * glm::inverse(v.camera.matrix()), v, rect, &s.options()};
}

}  // namespace

void EditorUi::draw_light_icons(const ViewRect& rect) {
  ImDrawList* dl = ImGui::GetForegroundDrawList();
  const Projector project = projector(session_, rect);
  const EditorState& s = session_.editor();
  session_.world().view<const engine::scene::PunctualLight, const engine::transform::WorldTransform>().each(
      [&](engine::ecs::Entity e, const engine::scene::PunctualLight& l, const engine::transform::WorldTransform& w) {
        const auto c = project(w.translation);
        if (!c) return;
        const glm::vec3 k = glm::clamp(l.color, 0.0f, 1.0f);
        const ImU32 colour = l.enabled ? IM_COL32(static_cast<int>(k.r * 255), static_cast<int>(k.g * 255), static_cast<int>(k.b * 255), 255)
                                       : IM_COL32(90, 90, 90, 255);
        dl->AddCircleFilled(*c, 6.0f, colour, 12);
        dl->AddCircle(*c, 9.0f, s.selected == e ? IM_COL32(255, 230, 90, 255) : IM_COL32(20, 20, 20, 255), 12, 2.0f);
      });
}

void EditorUi::draw_gizmo(const ViewRect& rect) {
  EditorState& s = session_.editor();
  if (s.selected.is_null()) return;
  ImDrawList* dl = ImGui::GetForegroundDrawList();
  const Projector project = projector(session_, rect);
  const bool rings = s.mode == GizmoMode::Rotate;
  const GizmoHandle handles[3] = {rings ? GizmoHandle::RX : GizmoHandle::X, rings ? GizmoHandle::RY : GizmoHandle::Y,
                                  rings ? GizmoHandle::RZ : GizmoHandle::Z};
  for (int a = 0; a < 3; ++a) {
    const HandleGeometry g = handle_geometry(session_.world(), s, project.view, handles[a]);
    if (!g.visible) continue;
    const bool hot = s.active == handles[a] || (s.active == GizmoHandle::None && s.hovered == handles[a]);
    const ImU32 c = axis_colour(a, hot);
    if (!rings) {
      const auto p0 = project(g.pivot + 0.15f * g.size * g.axis), p1 = project(g.pivot + g.size * g.axis);
      if (!p0 || !p1) continue;
      dl->AddLine(*p0, *p1, c, hot ? 4.0f : 3.0f);
      dl->AddCircleFilled(*p1, hot ? 7.0f : 6.0f, c);
    } else {
      const glm::vec3 u = ed::ring_reference(g.axis), v = glm::cross(g.axis, u);
      ImVec2 pts[65];
      int n = 0;
      for (int i = 0; i <= 64; ++i) {
        const float t = 6.2831853f * static_cast<float>(i) / 64.0f;
        if (const auto p = project(g.pivot + g.size * (std::cos(t) * u + std::sin(t) * v))) pts[n++] = *p;
      }
      if (n > 1) dl->AddPolyline(pts, n, c, 0, hot ? 4.0f : 2.5f);
    }
  }
  if (rings) return;
  // The plane squares, coloured by their normal's axis.
  const GizmoHandle planes[3] = {GizmoHandle::YZ, GizmoHandle::ZX, GizmoHandle::XY};  // normals X, Y, Z
  for (int a = 0; a < 3; ++a) {
    const HandleGeometry g = handle_geometry(session_.world(), s, project.view, planes[a]);
    if (!g.visible) continue;
    const bool hot = s.active == planes[a] || (s.active == GizmoHandle::None && s.hovered == planes[a]);
    const float lo = 0.2f * g.size, hi = 0.45f * g.size;
    const auto p0 = project(g.pivot + lo * g.axis + lo * g.axis2), p1 = project(g.pivot + hi * g.axis + lo * g.axis2);
    const auto p2 = project(g.pivot + hi * g.axis + hi * g.axis2), p3 = project(g.pivot + lo * g.axis + hi * g.axis2);
    if (!p0 || !p1 || !p2 || !p3) continue;
    const ImU32 c = axis_colour(a, hot);
    dl->AddQuadFilled(*p0, *p1, *p2, *p3, (c & 0x00ffffffu) | (hot ? 0xb0000000u : 0x60000000u));
    dl->AddQuad(*p0, *p1, *p2, *p3, c, 1.5f);
  }
}

void EditorUi::draw_probes(const ViewRect& rect) {
  // A debug overlay on the game view, under every panel and the menu bar
  // (the background list, after the frame's image), clipped to the view.
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  dl->PushClipRect(ImVec2(rect.min.x, rect.min.y), ImVec2(rect.max.x, rect.max.y), true);
  const Projector project = projector(session_, rect);
  const glm::vec3 eye = project.view.camera.translation;
  const glm::vec3 forward = project.view.camera.rotation * glm::vec3(0.0f, 0.0f, -1.0f);
  // A probe closer than this (in front of the eye) is not drawn; farther
  // ones shrink with distance, and none is drawn larger than max_radius.
  constexpr float kNearest = 0.25f;
  const float max_radius = 0.02f * (rect.max.y - rect.min.y);
  for (const auto& field : transgi::runtime::probe_fields(session_.world())) {
    const auto& grid = field->grid();
    // The volume's box.
    for (int e = 0; e < 12; ++e) {
      const int axis = e / 4, k = e % 4;
      glm::vec3 a = grid.min, b = grid.min;
      const int o1 = (axis + 1) % 3, o2 = (axis + 2) % 3;
      if (k & 1) a[o1] = b[o1] = grid.max[o1];
      if (k & 2) a[o2] = b[o2] = grid.max[o2];
      b[axis] = grid.max[axis];
      const auto pa = project(a), pb = project(b);
      if (pa && pb) dl->AddLine(*pa, *pb, IM_COL32(255, 255, 255, 120), 1.0f);
    }
    // Each probe as a small sphere: discs shaded by the SH irradiance toward
    // the viewer and toward four sides, so a probe's light direction shows.
    const std::vector<float>& sh = field->light_sh_all();
    const float radius_world = 0.06f;
    for (int i = 0; i < grid.count(); ++i) {
      const glm::vec3 p = grid.position(i);
      if (glm::dot(p - eye, forward) < kNearest) continue;
      const auto c = project(p);
      const auto edge = project(p + radius_world * glm::normalize(glm::cross(p - eye, glm::vec3(0, 1, 0)) + glm::vec3(1e-6f)));
      if (!c || !edge) continue;
      const float r = std::clamp(std::hypot(edge->x - c->x, edge->y - c->y), 2.0f, max_radius);
      const glm::vec3 to_eye = glm::normalize(eye - p);
      auto shade = [&](const glm::vec3& n) {
        const glm::vec3 e = transgi::shading::sh_irradiance(sh.data() + static_cast<std::size_t>(i) * 75, n) / 3.14159265f;
        const glm::vec3 srgb = glm::pow(glm::clamp(e * std::exp2(exposure_), 0.0f, 1.0f), glm::vec3(1.0f / 2.2f));
        return IM_COL32(static_cast<int>(srgb.r * 255), static_cast<int>(srgb.g * 255), static_cast<int>(srgb.b * 255), 255);
      };
      dl->AddCircleFilled(*c, r, shade(to_eye), 16);
      const glm::vec3 right = glm::normalize(glm::cross(to_eye, glm::vec3(0, 1, 0)) + glm::vec3(1e-6f)), up = glm::cross(right, to_eye);
      const glm::vec3 dirs[4] = {right, -right, up, -up};
      const ImVec2 offs[4] = {ImVec2(0.5f * r, 0), ImVec2(-0.5f * r, 0), ImVec2(0, -0.5f * r), ImVec2(0, 0.5f * r)};
      for (int k = 0; k < 4; ++k)
        dl->AddCircleFilled(ImVec2(c->x + offs[k].x, c->y + offs[k].y), 0.4f * r, shade(glm::normalize(to_eye + dirs[k])), 12);
    }
  }
  dl->PopClipRect();
}

}  // namespace game
