#pragma once
// The editor's Dear ImGui layer over the game view: a menu bar, the entity
// hierarchy, the inspector, the log, the stats overlay, the gizmo and the
// probe visualisation. It reads the session and writes only through the
// session, the ECS and EditorState; selection and drags are decided by
// update_editor() (editor_tools.h), which the game's frame() runs.
#include <deque>
#include <map>
#include <vector>
#include <string>

#include <glm/glm.hpp>
#include <imgui.h>

#include "play/game_session.h"

namespace game {

// Where the game image is drawn in the window (pixels, y down).
struct ViewRect {
  glm::vec2 min{0.0f}, max{1.0f};
  [[nodiscard]] bool contains(const glm::vec2& p) const { return glm::all(glm::greaterThanEqual(p, min)) && glm::all(glm::lessThan(p, max)); }
  // Window pixel -> pixel of the game image.
  [[nodiscard]] glm::vec2 to_game(const glm::vec2& p, const GameOptions& o) const {
    return (p - min) / (max - min) * glm::vec2(static_cast<float>(o.width), static_cast<float>(o.height));
  }
  [[nodiscard]] glm::vec2 to_window(const glm::vec2& g, const GameOptions& o) const {
    return min + g / glm::vec2(static_cast<float>(o.width), static_cast<float>(o.height)) * (max - min);
  }
};

class EditorUi {
 public:
  explicit EditorUi(GameSession& session) : session_(session) {}
  // The game view's rectangle for this frame (below the menu bar, the
  // image's aspect kept).
  [[nodiscard]] ViewRect view_rect() const;
  // frame_texture: the game image to draw in the view, or null where the
  // presenter has put it under the UI already (Vulkan: a blit).
  void draw(ImTextureID frame_texture);
  [[nodiscard]] float exposure() const { return exposure_; }
  [[nodiscard]] bool quit_requested() const { return quit_; }
  void show_probes(bool on) { show_probes_ = on; }
  // The inspector's width in font heights: wide enough for its longest
  // labels; the log panel sits between it and the hierarchy.
  static constexpr float kInspectorWidthEms = 28.0f;
  // The column every inspector widget leaves its label, in font heights.
  static constexpr float kLabelColumnEms = 11.5f;

 private:
  void menu_bar();
  void hierarchy();
  void hierarchy_node(engine::ecs::Entity e, const std::map<engine::ecs::Entity, std::vector<engine::ecs::Entity>>& children_of);
  void inspector();
  void gi_settings();
  void log_panel();
  void stats_overlay(const ViewRect& view);
  void draw_gizmo(const ViewRect& view);
  void draw_light_icons(const ViewRect& view);
  void draw_probes(const ViewRect& view);
  void save_level();
  void reload_shaders();  // F5: shader hot reload, errors to the log

  GameSession& session_;
  float exposure_ = 0.0f;
  bool quit_ = false, show_stats_ = true, show_probes_ = false, show_editor_ = true;
  std::deque<float> frame_ms_;
  std::string status_;
  std::uint64_t log_seen_ = 0;
  // The Transform before an inspector edit, for its undo entry.
  bool editing_transform_ = false;
  engine::transform::Transform edit_start_;
};

}  // namespace game
