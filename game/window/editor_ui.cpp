#include "window/editor_ui.h"

#include <algorithm>
#include <cstdio>

#include "engine/core/log.h"
#include "runtime/gi_frame.h"

namespace game {

ViewRect EditorUi::view_rect() const {
  const ImGuiIO& io = ImGui::GetIO();
  const float top = ImGui::GetFrameHeight();  // the menu bar
  const glm::vec2 avail(io.DisplaySize.x, std::max(1.0f, io.DisplaySize.y - top));
  const GameOptions& o = session_.options();
  const float aspect = static_cast<float>(o.width) / static_cast<float>(o.height);
  glm::vec2 size = avail;
  if (avail.x / avail.y > aspect) size.x = avail.y * aspect;
  else size.y = avail.x / aspect;
  ViewRect r;
  r.min = glm::vec2((avail.x - size.x) * 0.5f, top + (avail.y - size.y) * 0.5f);
  r.max = r.min + size;
  return r;
}

void EditorUi::draw(ImTextureID frame_texture) {
  const ViewRect view = view_rect();
  if (frame_texture)
    ImGui::GetBackgroundDrawList()->AddImage(frame_texture, ImVec2(view.min.x, view.min.y), ImVec2(view.max.x, view.max.y));
  frame_ms_.push_back(static_cast<float>(session_.last_frame_ms()));
  while (frame_ms_.size() > 240) frame_ms_.pop_front();
  menu_bar();
  if (show_editor_) {
    hierarchy();
    inspector();
    log_panel();
  }
  if (show_stats_) stats_overlay(view);
  if (show_probes_) draw_probes(view);
  if (show_editor_) draw_light_icons(view);
  draw_gizmo(view);
}

void EditorUi::menu_bar() {
  if (!ImGui::BeginMainMenuBar()) return;
  EditorState& ed = session_.editor();
  if (ImGui::BeginMenu("File")) {
    if (ImGui::MenuItem("Save level", "Ctrl+S")) save_level();
    if (ImGui::MenuItem("Quit", "Esc")) quit_ = true;
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("Edit")) {
    if (ImGui::MenuItem("Undo", "Ctrl+Z", false, ed.undo.undo_count() > 0)) ed.undo.undo(session_.world());
    if (ImGui::MenuItem("Redo", "Ctrl+Y", false, ed.undo.redo_count() > 0)) ed.undo.redo(session_.world());
    ImGui::Separator();
    if (ImGui::MenuItem("Translate gizmo", "T", ed.mode == GizmoMode::Translate)) ed.mode = GizmoMode::Translate;
    if (ImGui::MenuItem("Rotate gizmo", "R", ed.mode == GizmoMode::Rotate)) ed.mode = GizmoMode::Rotate;
    ImGui::EndMenu();
  }
  if (ImGui::BeginMenu("View")) {
    for (GameMethod m : {GameMethod::TransGI, GameMethod::Ddgi, GameMethod::Reference})
      if (ImGui::MenuItem(method_name(m), nullptr, session_.method() == m)) session_.set_method(m);
    ImGui::Separator();
    for (const char* pass : {"full", "gi", "direct"})
      if (ImGui::MenuItem(pass, nullptr, session_.view_name() == pass)) session_.set_view(pass);
    ImGui::Separator();
    ImGui::MenuItem("Editor panels", "F1", &show_editor_);
    if (ImGui::MenuItem("Reload shaders", "F5")) reload_shaders();
    ImGui::MenuItem("Stats overlay", nullptr, &show_stats_);
    ImGui::MenuItem("Probes", nullptr, &show_probes_);
    ImGui::SliderFloat("Exposure", &exposure_, -4.0f, 4.0f, "%.1f stops");
    ImGui::EndMenu();
  }
  if (!status_.empty()) ImGui::TextDisabled("  %s", status_.c_str());
  ImGui::EndMainMenuBar();
  const engine::input::InputState& in = session_.input();
  if (!ImGui::GetIO().WantCaptureKeyboard) {
    if (in.was_pressed("T") && !in.is_down("ctrl")) ed.mode = GizmoMode::Translate;
    if (in.was_pressed("R") && !in.is_down("ctrl")) ed.mode = GizmoMode::Rotate;
    if (in.is_down("ctrl") && in.was_pressed("S")) save_level();
    if (in.was_pressed("F5")) reload_shaders();
  }
}

void EditorUi::reload_shaders() {
  const auto errors = session_.reload_shaders();
  // The first error in the menu bar; all of them are in the log panel.
  status_ = errors.empty() ? "shaders reloaded" : errors.front().substr(0, errors.front().find('\n'));
}

void EditorUi::stats_overlay(const ViewRect& view) {
  ImGui::SetNextWindowPos(ImVec2(std::max(view.min.x + 8, show_editor_ ? 256.0f : 0.0f), view.min.y + 8));
  ImGui::SetNextWindowBgAlpha(0.55f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoMove;
  if (!ImGui::Begin("Stats", nullptr, flags)) {
    ImGui::End();
    return;
  }
  const auto& f = session_.world().resource<transgi::runtime::GiFrame>();
  std::vector<float> ms(frame_ms_.begin(), frame_ms_.end());
  const float last = ms.empty() ? 0.0f : ms.back();
  ImGui::Text("%s, %s pass, %dx%d", method_name(session_.method()), session_.view_name().c_str(), session_.options().width,
              session_.options().height);
  ImGui::Text("frame %.1f ms (%.0f fps)", static_cast<double>(last), last > 0 ? 1000.0 / static_cast<double>(last) : 0.0);
  const float top = graph_top(ms);
  const std::string scale = "0-" + std::to_string(static_cast<int>(top)) + " ms, last 240 frames";
  ImGui::PlotLines("##frame", ms.data(), static_cast<int>(ms.size()), 0, scale.c_str(), 0.0f, top, ImVec2(300, 50));
  if (session_.method() == GameMethod::Reference)
    ImGui::Text("reference: %d spp (game time paused)", session_.reference_spp());
  // The shown method's own stages, three to a line.
  const auto stages = session_.stage_times();
  for (std::size_t i = 0; i < stages.size(); i += 3) {
    std::string line;
    for (std::size_t k = i; k < std::min(stages.size(), i + 3); ++k) {
      char item[64];
      std::snprintf(item, sizeof item, "%s%s %.1f", k > i ? "  " : "", stages[k].name.c_str(), stages[k].ms);
      line += item;
    }
    ImGui::TextUnformatted((line + (i + 3 >= stages.size() ? " ms" : "")).c_str());
  }
  const auto& p = f.probe_stats;
  if (session_.method() == GameMethod::TransGI)
    ImGui::Text("probes: %d traced, %d active, %d converged, %d skipped (buried %d, far %d)", p.traced, p.active, p.converged,
                p.buried + p.far, p.buried, p.far);
  ImGui::End();
}

void EditorUi::log_panel() {
  const ImGuiIO& io = ImGui::GetIO();
  ImGui::SetNextWindowPos(ImVec2(260, io.DisplaySize.y - 170), ImGuiCond_FirstUseEver);
  // Between the hierarchy and the inspector.
  ImGui::SetNextWindowSize(ImVec2(std::max(200.0f, io.DisplaySize.x - 260 - kInspectorWidthEms * ImGui::GetFontSize() - 16), 160),
                           ImGuiCond_FirstUseEver);
  if (!ImGui::Begin("Log")) {
    ImGui::End();
    return;
  }
  const auto& log = session_.world().resource<engine::core::Log>();
  for (const engine::core::LogEntry& e : log.entries()) {
    const ImVec4 colour = e.level == engine::core::LogLevel::Error     ? ImVec4(1.0f, 0.45f, 0.4f, 1.0f)
                          : e.level == engine::core::LogLevel::Warning ? ImVec4(1.0f, 0.85f, 0.4f, 1.0f)
                                                                       : ImVec4(0.85f, 0.85f, 0.85f, 1.0f);
    ImGui::TextColored(colour, "%s: %s", e.source.c_str(), e.text.c_str());
  }
  if (log.total() != log_seen_) ImGui::SetScrollHereY(1.0f);  // follow new entries
  log_seen_ = log.total();
  ImGui::End();
}

}  // namespace game
