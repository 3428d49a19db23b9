#include "window/window_run.h"

#include <cstdio>
#include <deque>
#include <stdexcept>

#include <GLFW/glfw3.h>
#include <imgui.h>

#include "engine/image/tonemap.h"
#include "play/input_queue.h"
#include "window/editor_ui.h"
#include "window/presenter.h"
#include "window/window_input.h"

namespace game {

namespace {

void glfw_error(int code, const char* text) { std::fprintf(stderr, "transgi-game: GLFW error %d: %s\n", code, text); }

// GLFW's callbacks queue every key and button change for the frame loop
// (play/input_queue.h). Installed before ImGui's, which chains to them.
std::vector<InputEvent>& queued_events() {
  static std::vector<InputEvent> events;
  return events;
}

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (action == GLFW_REPEAT) return;
  const std::string name = key_name(key);
  if (name.empty()) return;
  // Both Ctrl keys are "ctrl": releasing one while the other is held is not a release.
  if (name == "ctrl" && action == GLFW_RELEASE &&
      (glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS))
    return;
  queued_events().push_back({name, action == GLFW_PRESS, false});
}

void on_mouse_button(GLFWwindow*, int button, int action, int) {
  const char* name = button == GLFW_MOUSE_BUTTON_LEFT ? "mouse_left" : button == GLFW_MOUSE_BUTTON_RIGHT ? "mouse_right" : nullptr;
  if (name) queued_events().push_back({name, action == GLFW_PRESS, true});
}

struct Glfw {
  Glfw() {
    glfwSetErrorCallback(glfw_error);
    if (!glfwInit()) throw std::runtime_error("cannot open a window: no display (is DISPLAY set? try xvfb-run, or --headless)");
  }
  ~Glfw() { glfwTerminate(); }
};

}  // namespace

int run_window(const GameOptions& options, const WindowOptions& wo) {
  Glfw glfw;
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside whoever runs the game
  ImGui::StyleColorsDark();
  const auto install_callbacks = [](GLFWwindow* window) {
    glfwSetKeyCallback(window, on_key);
    glfwSetMouseButtonCallback(window, on_mouse_button);
  };
  // Chosen once: with the Vulkan backend the frames are presented on the
  // device the GI kernels run on, which the session is given.
  const char* title = "TransGI - sample level";
  std::unique_ptr<Presenter> presenter;
  try {
    presenter = options.backend == "vulkan" ? make_vulkan_presenter(wo.window_width, wo.window_height, title, install_callbacks)
                                            : make_gl_presenter(wo.window_width, wo.window_height, title, install_callbacks);
  } catch (...) {
    ImGui::DestroyContext();
    throw;
  }
  GameOptions game_options = options;
  game_options.host_gpu = presenter->device();
  std::printf("transgi-game: presenting through %s\n", presenter->name());
  GLFWwindow* window = presenter->window();

  int code = 0;
  {
    GameSession session(game_options);
    EditorUi ui(session);
    if (!wo.select.empty()) {
      session.editor().selected = session.find(wo.select);
      if (session.editor().selected.is_null()) throw std::runtime_error("--select: no entity named '" + wo.select + "'");
    }
    if (wo.gizmo != "translate" && wo.gizmo != "rotate") throw std::runtime_error("--gizmo: expected translate or rotate, got '" + wo.gizmo + "'");
    session.editor().mode = wo.gizmo == "rotate" ? GizmoMode::Rotate : GizmoMode::Translate;
    ui.show_probes(wo.probes);
    for (int frame = 0; !glfwWindowShouldClose(window) && (wo.frames <= 0 || frame < wo.frames); ++frame) {
      session.begin_input();
      glfwPollEvents();
      presenter->new_frame();
      ImGui::NewFrame();
      // The game view fills the window below the menu bar; the game sees
      // keys and the mouse only when ImGui does not want them.
      const ImGuiIO& io = ImGui::GetIO();
      engine::input::InputState& in = session.input();
      const ViewRect view = ui.view_rect();
      double mx = 0, my = 0;
      glfwGetCursorPos(window, &mx, &my);
      const glm::vec2 game_mouse = view.to_game({static_cast<float>(mx), static_cast<float>(my)}, session.options());
      in.move_mouse(game_mouse);
      const bool mouse_free = !io.WantCaptureMouse && view.contains({static_cast<float>(mx), static_cast<float>(my)});
      // Every change since the last frame, in order: a tap shorter than a
      // frame is not lost at a few frames a second.
      apply_input_events(in, queued_events(), !io.WantCaptureKeyboard, mouse_free);
      queued_events().clear();
      if (in.was_pressed("escape")) glfwSetWindowShouldClose(window, 1);

      session.frame();
      ui.draw(presenter->show(engine::image::to_srgb8(session.image(), ui.exposure())));
      if (ui.quit_requested()) glfwSetWindowShouldClose(window, 1);

      ImGui::Render();
      const bool last = wo.frames > 0 && frame + 1 == wo.frames;
      presenter->present(view, last ? wo.screenshot : std::filesystem::path());
      if (last && !wo.screenshot.empty()) std::printf("wrote %s\n", wo.screenshot.string().c_str());
    }
    std::printf("transgi-game: window closed after %llu frames\n", static_cast<unsigned long long>(session.frames()));
  }
  presenter.reset();
  ImGui::DestroyContext();
  return code;
}

}  // namespace game
