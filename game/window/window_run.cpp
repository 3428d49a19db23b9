#include "window/window_run.h"

#include <cstdio>
#include <deque>
#include <stdexcept>

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "engine/image/png.h"
#include "engine/image/tonemap.h"
#include "window/editor_ui.h"
#include "play/input_queue.h"
#include "window/window_input.h"

namespace game {

namespace {

void glfw_error(int code, const char* text) { std::fprintf(stderr, "transgi-game: GLFW error %d: %s\n", code, text); }

// The window's back buffer as a PNG (rows flipped: GL's origin is bottom-left).
void save_back_buffer(GLFWwindow* w, const std::filesystem::path& out) {
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(w, &fw, &fh);
  engine::image::Rgb8Image img(fw, fh);
  std::vector<std::uint8_t> rows(static_cast<std::size_t>(fw) * fh * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  for (int y = 0; y < fh; ++y)
    std::copy_n(rows.data() + static_cast<std::size_t>(fh - 1 - y) * fw * 3, static_cast<std::size_t>(fw) * 3, img.at(0, y));
  engine::image::write_png(out, img);
}

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

int run_window(const GameOptions& game_options, const WindowOptions& wo) {
  Glfw glfw;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(wo.window_width, wo.window_height, "TransGI - sample level", nullptr, nullptr);
  if (!window) throw std::runtime_error("cannot create an OpenGL 3.3 window (is an OpenGL driver, such as Mesa, installed?)");
  glfwMakeContextCurrent(window);
  glfwSwapInterval(0);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside whoever runs the game
  ImGui::StyleColorsDark();
  glfwSetKeyCallback(window, on_key);
  glfwSetMouseButtonCallback(window, on_mouse_button);
  ImGui_ImplGlfw_InitForOpenGL(window, true);  // chains to the callbacks above
  ImGui_ImplOpenGL3_Init("#version 330");

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
    GLuint texture = 0;
    glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (int frame = 0; !glfwWindowShouldClose(window) && (wo.frames <= 0 || frame < wo.frames); ++frame) {
      session.begin_input();
      glfwPollEvents();
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
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
      const engine::image::Rgb8Image shown = engine::image::to_srgb8(session.image(), ui.exposure());
      glBindTexture(GL_TEXTURE_2D, texture);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      if (!shown.pixels.empty())
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, shown.width, shown.height, 0, GL_RGB, GL_UNSIGNED_BYTE, shown.pixels.data());
      ui.draw(reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(texture)));
      if (ui.quit_requested()) glfwSetWindowShouldClose(window, 1);

      ImGui::Render();
      int fw = 0, fh = 0;
      glfwGetFramebufferSize(window, &fw, &fh);
      glViewport(0, 0, fw, fh);
      glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
      glClear(GL_COLOR_BUFFER_BIT);
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      const bool last = wo.frames > 0 && frame + 1 == wo.frames;
      if (last && !wo.screenshot.empty()) {
        save_back_buffer(window, wo.screenshot);
        std::printf("wrote %s\n", wo.screenshot.string().c_str());
      }
      glfwSwapBuffers(window);
    }
    glDeleteTextures(1, &texture);
    std::printf("transgi-game: window closed after %llu frames\n", static_cast<unsigned long long>(session.frames()));
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  return code;
}

}  // namespace game
