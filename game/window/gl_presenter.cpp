// The OpenGL 3.3 presenter (presenter.h): the game image as a texture the
// editor draws, ImGui's OpenGL backend, glfwSwapBuffers.
#include <cstdint>
#include <stdexcept>
#include <vector>

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "engine/image/png.h"
#include "window/presenter.h"

namespace game {

namespace {

class GlPresenter final : public Presenter {
 public:
  GlPresenter(int width, int height, const char* title, const InstallCallbacks& install_callbacks) {
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    window_ = glfwCreateWindow(width, height, title, nullptr, nullptr);
    if (!window_) throw std::runtime_error("cannot create an OpenGL 3.3 window (is an OpenGL driver, such as Mesa, installed?)");
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(0);
    install_callbacks(window_);
    ImGui_ImplGlfw_InitForOpenGL(window_, true);  // chains to the callbacks above
    ImGui_ImplOpenGL3_Init("#version 330");
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  }
  ~GlPresenter() override {
    glDeleteTextures(1, &texture_);
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    glfwDestroyWindow(window_);
  }
  GlPresenter(const GlPresenter&) = delete;
  GlPresenter& operator=(const GlPresenter&) = delete;

  [[nodiscard]] GLFWwindow* window() const override { return window_; }
  void new_frame() override {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
  }
  ImTextureID show(const engine::image::Rgb8Image& image) override {
    glBindTexture(GL_TEXTURE_2D, texture_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    if (!image.pixels.empty())
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, image.width, image.height, 0, GL_RGB, GL_UNSIGNED_BYTE, image.pixels.data());
    return reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(texture_));
  }
  void present(const ViewRect&, const std::filesystem::path& screenshot) override {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window_, &fw, &fh);
    glViewport(0, 0, fw, fh);
    glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (!screenshot.empty()) save_back_buffer(fw, fh, screenshot);
    glfwSwapBuffers(window_);
  }
  [[nodiscard]] const char* name() const override { return "OpenGL 3.3"; }

 private:
  // The back buffer as a PNG (rows flipped: GL's origin is bottom-left).
  static void save_back_buffer(int fw, int fh, const std::filesystem::path& out) {
    engine::image::Rgb8Image img(fw, fh);
    std::vector<std::uint8_t> rows(static_cast<std::size_t>(fw) * static_cast<std::size_t>(fh) * 3);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, fw, fh, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
    for (int y = 0; y < fh; ++y)
      std::copy_n(rows.data() + static_cast<std::size_t>(fh - 1 - y) * static_cast<std::size_t>(fw) * 3,
                  static_cast<std::size_t>(fw) * 3, img.at(0, y));
    engine::image::write_png(out, img);
  }

  GLFWwindow* window_ = nullptr;
  GLuint texture_ = 0;
};

}  // namespace

std::unique_ptr<Presenter> make_gl_presenter(int width, int height, const char* title, const InstallCallbacks& install_callbacks) {
  return std::make_unique<GlPresenter>(width, height, title, install_callbacks);
}

}  // namespace game
