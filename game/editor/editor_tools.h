#pragma once
// The editor's selection and gizmo drags, driven only by InputState and the
// camera, so a window, a replay file and a test drive the same code. Drawing
// (ImGui) reads EditorState and handle_geometry(); it decides nothing.
//
// A left click on a handle of the selection's gizmo starts a drag; anywhere
// else it selects what is under the cursor (meshes through Embree, lights by
// their icon). A drag sets the Transform to the start transform plus the
// delta since the press (Ctrl snaps: 0.25 m, 15 degrees); releasing records
// one undo entry. Ctrl+Z / Ctrl+Y undo and redo.
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "engine/ecs/world.h"
#include "engine/editor/undo_stack.h"
#include "engine/input/input_state.h"
#include "engine/transform/transform.h"

namespace game {

enum class GizmoMode { Translate, Rotate };
// X, Y, Z: translate along an axis; XY, YZ, ZX: translate in a plane (the
// square between two axes); RX, RY, RZ: rotate about an axis (a ring).
enum class GizmoHandle { None, X, Y, Z, XY, YZ, ZX, RX, RY, RZ };

struct EditorView {
  engine::transform::Similarity camera;  // world transform of the camera (looks down -Z)
  float fov_y = 1.0f, aspect = 16.0f / 9.0f;
  glm::vec2 viewport{640, 360};
};

struct EditorState {
  engine::ecs::Entity selected;
  GizmoMode mode = GizmoMode::Translate;
  GizmoHandle hovered = GizmoHandle::None, active = GizmoHandle::None;
  // The gizmo's length as a fraction of the view's height, the same at every
  // distance and resolution. Higher = easier to grab, at the cost of
  // covering more of the scene.
  float gizmo_fraction = 0.15f;
  // Higher = handles easier to hit at the cost of taking clicks meant for the scene.
  float pick_pixels = 8.0f;
  float translate_snap = 0.25f, rotate_snap_degrees = 15.0f;
  engine::editor::UndoStack undo;
  // The drag in progress.
  engine::transform::Transform start;
  engine::transform::Similarity parent;
  glm::vec3 pivot{0.0f};
  float start_param = 0.0f, angle = 0.0f, last_angle = 0.0f;
  glm::vec3 start_hit{0.0f};  // plane drags: where the press met the plane
  // Ring drags of a ring seen near edge-on: by the cursor's motion along the
  // ring's tangent on screen where it was grabbed, one radian per ring radius.
  bool ring_by_screen = false;
  glm::vec2 grab_mouse{0.0f}, screen_tangent{0.0f};
  float pixels_per_radian = 1.0f;
  std::size_t drags = 0;  // finished drags, for tests and the stats overlay
};

// One handle's geometry in world space around `pivot`: an axis segment of
// length `size` (translate), a square from 0.2 to 0.45 size along `axis` and
// `axis2` with normal `axis` x `axis2` (plane), or a ring of radius `size`
// about `axis` (rotate).
struct HandleGeometry {
  // The object's origin, or the centre of its world bounds when the origin
  // lies outside them (meshes exported with world-space vertices and an
  // identity transform, common in converted content).
  glm::vec3 pivot{0.0f}, axis{0.0f}, axis2{0.0f};
  float size = 0.0f;
  bool visible = false;  // false for an axis or square seen end- or edge-on (a ring always shows)
};
HandleGeometry handle_geometry(const engine::ecs::World& world, const EditorState& s, const EditorView& view, GizmoHandle h);
// Where a person would grab the handle, in pixels (for replays and tests).
std::optional<glm::vec2> handle_grab_pixel(const engine::ecs::World& world, const EditorState& s, const EditorView& view,
                                           GizmoHandle h);

// Applies this frame's mouse and keys.
void update_editor(engine::ecs::World& world, EditorState& s, const engine::input::InputState& in, const EditorView& view);

// The entity under a pixel: a mesh through the ray-tracing scene, or a
// light whose icon (its projected position) lies within pick_pixels.
engine::ecs::Entity pick_entity(engine::ecs::World& world, const EditorView& view, const glm::vec2& pixel, float pick_pixels);

GizmoHandle parse_handle(const std::string& name);

}  // namespace game
