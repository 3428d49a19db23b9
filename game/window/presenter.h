#pragma once
// How the window shows a frame: the game image under the editor's ImGui
// layer, then the swap. Two implementations, chosen once when the window
// opens: OpenGL 3.3 (gl_presenter.cpp, the default) and a Vulkan swapchain on
// the device the GI kernels run on (vulkan_presenter.cpp, with --backend
// vulkan). Each owns the GLFW window and its ImGui renderer backend.
#include <filesystem>
#include <functional>
#include <memory>

#include <imgui.h>

#include "engine/gpu/vulkan_context.h"
#include "engine/image/image.h"
#include "window/editor_ui.h"

struct GLFWwindow;

namespace game {

class Presenter {
 public:
  virtual ~Presenter() = default;
  [[nodiscard]] virtual GLFWwindow* window() const = 0;
  // Starts the ImGui renderer backend's frame (before ImGui::NewFrame).
  virtual void new_frame() = 0;
  // This frame's game image. Returns the texture the editor draws in the
  // view, or null where the presenter puts the image under the UI itself.
  virtual ImTextureID show(const engine::image::Rgb8Image& image) = 0;
  // After ImGui::Render: the image in `view` (window coordinates), the UI
  // over it, presented; with a path, the presented pixels written there as
  // a PNG first.
  virtual void present(const ViewRect& view, const std::filesystem::path& screenshot) = 0;
  // The device the frames are presented on, for the GI kernels (null: none).
  [[nodiscard]] virtual std::shared_ptr<engine::gpu::VulkanContext> device() const { return nullptr; }
  [[nodiscard]] virtual const char* name() const = 0;
};

// install_callbacks(window) runs before ImGui's GLFW backend is installed
// (ImGui chains to the callbacks it finds). An ImGui context must exist.
// Both throw std::runtime_error with what is missing (a display, a driver).
using InstallCallbacks = std::function<void(GLFWwindow*)>;
std::unique_ptr<Presenter> make_gl_presenter(int width, int height, const char* title, const InstallCallbacks& install_callbacks);
std::unique_ptr<Presenter> make_vulkan_presenter(int width, int height, const char* title,
                                                 const InstallCallbacks& install_callbacks);

}  // namespace game
