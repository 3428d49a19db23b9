// The Vulkan presenter (presenter.h): a swapchain on the device the GI
// kernels run on (--backend vulkan). Each frame the game image is written to
// a staging buffer, copied into an image and blitted (scaled) into the view's
// rectangle of the swapchain image; ImGui draws over it in a render pass that
// keeps what is there, and the image is presented. ImGui 1.86's Vulkan
// backend draws no user textures, hence the blit under the UI.
#include <algorithm>
#include <array>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/device_image.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/gpu_error.h"
#include "engine/image/png.h"
#include "window/presenter.h"

namespace game {

namespace {

void check_imgui(VkResult r) {
  if (r != VK_SUCCESS) std::fprintf(stderr, "transgi-game: ImGui's Vulkan backend: %s\n", engine::gpu::vk_result_name(r).c_str());
}

// One image layout change, waiting for `src` work before `dst` work.
void transition(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to, VkAccessFlags src_access,
                VkAccessFlags dst_access, VkPipelineStageFlags src_stage, VkPipelineStageFlags dst_stage) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.oldLayout = from;
  b.newLayout = to;
  b.srcAccessMask = src_access;
  b.dstAccessMask = dst_access;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

class VulkanPresenter final : public Presenter {
 public:
  VulkanPresenter(int width, int height, const char* title, const InstallCallbacks& install_callbacks) {
    if (!glfwVulkanSupported()) throw std::runtime_error("--backend vulkan: GLFW finds no Vulkan loader or driver for windows");
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    window_ = glfwCreateWindow(width, height, title, nullptr, nullptr);
    if (!window_) throw std::runtime_error("cannot create a window for Vulkan (is a display there? try xvfb-run)");
    try {
      make_device();
      make_frame_objects();
      make_swapchain();
      install_callbacks(window_);
      ImGui_ImplGlfw_InitForVulkan(window_, true);  // chains to the callbacks above
      imgui_glfw_ = true;
      init_imgui();
    } catch (...) {
      destroy();
      throw;
    }
  }
  ~VulkanPresenter() override { destroy(); }
  VulkanPresenter(const VulkanPresenter&) = delete;
  VulkanPresenter& operator=(const VulkanPresenter&) = delete;

  [[nodiscard]] GLFWwindow* window() const override { return window_; }
  [[nodiscard]] std::shared_ptr<engine::gpu::VulkanContext> device() const override { return ctx_; }
  [[nodiscard]] const char* name() const override { return "Vulkan swapchain"; }

  void new_frame() override {
    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
  }

  ImTextureID show(const engine::image::Rgb8Image& image) override {
    game_width_ = image.width;
    game_height_ = image.height;
    if (image.pixels.empty()) return nullptr;
    const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
    if (staging_.size() < pixels * 4) staging_ = engine::gpu::GpuBuffer(*ctx_, pixels * 4);
    const auto rgba = staging_.mapped_as<std::uint8_t>(pixels * 4);
    for (std::size_t i = 0; i < pixels; ++i) {
      std::memcpy(&rgba[i * 4], &image.pixels[i * 3], 3);
      rgba[i * 4 + 3] = 255;
    }
    if (image.width != image_width_ || image.height != image_height_) make_game_image(image.width, image.height);
    return nullptr;  // blitted under the UI in present()
  }

  void present(const ViewRect& view, const std::filesystem::path& screenshot) override {
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window_, &fw, &fh);
    if (fw <= 0 || fh <= 0) return;  // minimised
    if (static_cast<std::uint32_t>(fw) != extent_.width || static_cast<std::uint32_t>(fh) != extent_.height) remake_swapchain();
    std::uint32_t index = 0;
    const VkResult acquired = vkAcquireNextImageKHR(ctx_->device(), swapchain_, UINT64_MAX, acquired_, VK_NULL_HANDLE, &index);
    if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
      remake_swapchain();
      return;
    }
    if (acquired != VK_SUBOPTIMAL_KHR) ENGINE_VK_CHECK(acquired);
    ENGINE_VK_CHECK(vkResetCommandBuffer(cmd_, 0));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    ENGINE_VK_CHECK(vkBeginCommandBuffer(cmd_, &begin));
    record_view(images_[index], view, fw, fh);
    record_ui(index);
    const bool shoot = !screenshot.empty() && can_read_back_;
    if (shoot) record_read_back(images_[index]);
    ENGINE_VK_CHECK(vkEndCommandBuffer(cmd_));
    const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &acquired_;
    submit.pWaitDstStageMask = &wait_stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd_;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &rendered_;
    ENGINE_VK_CHECK(vkResetFences(ctx_->device(), 1, &fence_));
    ENGINE_VK_CHECK(vkQueueSubmit(ctx_->queue(), 1, &submit, fence_));
    // One frame in flight: the kernels' next submission and this frame's
    // staging buffer wait for this one.
    ENGINE_VK_CHECK(vkWaitForFences(ctx_->device(), 1, &fence_, VK_TRUE, UINT64_MAX));
    if (shoot) write_screenshot(screenshot);
    else if (!screenshot.empty())
      std::fprintf(stderr, "transgi-game: --screenshot: this swapchain's images cannot be read back (no transfer-source use)\n");
    VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    info.waitSemaphoreCount = 1;
    info.pWaitSemaphores = &rendered_;
    info.swapchainCount = 1;
    info.pSwapchains = &swapchain_;
    info.pImageIndices = &index;
    const VkResult presented = vkQueuePresentKHR(ctx_->queue(), &info);
    if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR) remake_swapchain();
    else ENGINE_VK_CHECK(presented);
  }

 private:
  // The kernels' context, made on a device whose queue presents to this
  // window, with the swapchain extension.
  void make_device() {
    std::uint32_t count = 0;
    const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&count);
    if (!glfw_extensions) throw std::runtime_error("--backend vulkan: GLFW names no instance extensions for window surfaces");
    engine::gpu::GpuOptions options;
    options.instance_extensions.assign(glfw_extensions, glfw_extensions + count);
    options.device_extensions = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
    options.queue_family_accepts = [](VkInstance instance, VkPhysicalDevice physical, std::uint32_t family) {
      std::uint32_t n = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(physical, &n, nullptr);
      std::vector<VkQueueFamilyProperties> families(n);
      vkGetPhysicalDeviceQueueFamilyProperties(physical, &n, families.data());
      return family < n && (families[family].queueFlags & VK_QUEUE_GRAPHICS_BIT) &&
             glfwGetPhysicalDevicePresentationSupport(instance, physical, family) == GLFW_TRUE;
    };
    std::string why;
    ctx_ = engine::gpu::VulkanContext::create(options, &why);
    if (!ctx_) throw std::runtime_error("--backend vulkan: no device can both run the GI kernels and present to the window: " + why);
    ENGINE_VK_CHECK(glfwCreateWindowSurface(ctx_->instance(), window_, nullptr, &surface_));
    VkBool32 supported = VK_FALSE;
    vkGetPhysicalDeviceSurfaceSupportKHR(ctx_->physical_device(), ctx_->queue_family(), surface_, &supported);
    if (!supported) throw std::runtime_error("--backend vulkan: the chosen queue cannot present to this window");
  }

  void make_frame_objects() {
    const VkDevice d = ctx_->device();
    VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pci.queueFamilyIndex = ctx_->queue_family();
    ENGINE_VK_CHECK(vkCreateCommandPool(d, &pci, nullptr, &pool_));
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    ENGINE_VK_CHECK(vkAllocateCommandBuffers(d, &ai, &cmd_));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    ENGINE_VK_CHECK(vkCreateFence(d, &fci, nullptr, &fence_));
    VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    ENGINE_VK_CHECK(vkCreateSemaphore(d, &sci, nullptr, &acquired_));
    ENGINE_VK_CHECK(vkCreateSemaphore(d, &sci, nullptr, &rendered_));
  }

  // The surface's format: 8-bit UNORM (the image is sRGB-encoded already,
  // as the OpenGL window shows it), blittable into.
  VkSurfaceFormatKHR choose_format() const {
    std::uint32_t n = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_->physical_device(), surface_, &n, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(n);
    vkGetPhysicalDeviceSurfaceFormatsKHR(ctx_->physical_device(), surface_, &n, formats.data());
    for (const VkFormat want : {VK_FORMAT_B8G8R8A8_UNORM, VK_FORMAT_R8G8B8A8_UNORM})
      for (const VkSurfaceFormatKHR& f : formats)
        if (f.format == want) {
          VkFormatProperties props;
          vkGetPhysicalDeviceFormatProperties(ctx_->physical_device(), f.format, &props);
          if (props.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT) return f;
        }
    throw std::runtime_error("--backend vulkan: the window offers no 8-bit UNORM format the device can blit into");
  }

  void make_swapchain() {
    const VkDevice d = ctx_->device();
    VkSurfaceCapabilitiesKHR caps;
    ENGINE_VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(ctx_->physical_device(), surface_, &caps));
    if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
      throw std::runtime_error("--backend vulkan: the window's images cannot be written by transfers");
    const VkSurfaceFormatKHR format = choose_format();
    format_ = format.format;
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window_, &fw, &fh);
    extent_ = caps.currentExtent.width != UINT32_MAX
                  ? caps.currentExtent
                  : VkExtent2D{std::clamp(static_cast<std::uint32_t>(std::max(fw, 1)), caps.minImageExtent.width, caps.maxImageExtent.width),
                               std::clamp(static_cast<std::uint32_t>(std::max(fh, 1)), caps.minImageExtent.height, caps.maxImageExtent.height)};
    std::uint32_t n = 0;
    vkGetPhysicalDeviceSurfacePresentModesKHR(ctx_->physical_device(), surface_, &n, nullptr);
    std::vector<VkPresentModeKHR> modes(n);
    vkGetPhysicalDeviceSurfacePresentModesKHR(ctx_->physical_device(), surface_, &n, modes.data());
    // Unthrottled, as the OpenGL window (swap interval 0); FIFO is always there.
    VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR;
    for (const VkPresentModeKHR want : {VK_PRESENT_MODE_IMMEDIATE_KHR, VK_PRESENT_MODE_MAILBOX_KHR})
      if (mode == VK_PRESENT_MODE_FIFO_KHR && std::find(modes.begin(), modes.end(), want) != modes.end()) mode = want;
    min_images_ = std::max(2u, caps.minImageCount);
    std::uint32_t images = caps.minImageCount + 1;
    if (caps.maxImageCount > 0) images = std::min(images, caps.maxImageCount);
    can_read_back_ = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;
    VkSwapchainCreateInfoKHR sci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    sci.surface = surface_;
    sci.minImageCount = images;
    sci.imageFormat = format.format;
    sci.imageColorSpace = format.colorSpace;
    sci.imageExtent = extent_;
    sci.imageArrayLayers = 1;
    sci.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                     (can_read_back_ ? static_cast<VkImageUsageFlags>(VK_IMAGE_USAGE_TRANSFER_SRC_BIT) : 0u);
    sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    sci.preTransform = caps.currentTransform;
    sci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    sci.presentMode = mode;
    sci.clipped = VK_TRUE;
    ENGINE_VK_CHECK(vkCreateSwapchainKHR(d, &sci, nullptr, &swapchain_));
    ENGINE_VK_CHECK(vkGetSwapchainImagesKHR(d, swapchain_, &n, nullptr));
    images_.resize(n);
    ENGINE_VK_CHECK(vkGetSwapchainImagesKHR(d, swapchain_, &n, images_.data()));
    if (!render_pass_) make_render_pass();
    for (VkImage image : images_) {
      VkImageViewCreateInfo vci{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      vci.image = image;
      vci.viewType = VK_IMAGE_VIEW_TYPE_2D;
      vci.format = format_;
      vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
      VkImageView view = VK_NULL_HANDLE;
      ENGINE_VK_CHECK(vkCreateImageView(d, &vci, nullptr, &view));
      views_.push_back(view);
      VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
      fci.renderPass = render_pass_;
      fci.attachmentCount = 1;
      fci.pAttachments = &view;
      fci.width = extent_.width;
      fci.height = extent_.height;
      fci.layers = 1;
      VkFramebuffer fb = VK_NULL_HANDLE;
      ENGINE_VK_CHECK(vkCreateFramebuffer(d, &fci, nullptr, &fb));
      framebuffers_.push_back(fb);
    }
  }

  // ImGui draws over the blitted view: the pass keeps what is there.
  void make_render_pass() {
    VkAttachmentDescription color{};
    color.format = format_;
    color.samples = VK_SAMPLE_COUNT_1_BIT;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    color.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &ref;
    VkRenderPassCreateInfo rci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rci.attachmentCount = 1;
    rci.pAttachments = &color;
    rci.subpassCount = 1;
    rci.pSubpasses = &subpass;
    ENGINE_VK_CHECK(vkCreateRenderPass(ctx_->device(), &rci, nullptr, &render_pass_));
  }

  void destroy_swapchain() {
    const VkDevice d = ctx_->device();
    for (VkFramebuffer fb : framebuffers_) vkDestroyFramebuffer(d, fb, nullptr);
    for (VkImageView v : views_) vkDestroyImageView(d, v, nullptr);
    framebuffers_.clear();
    views_.clear();
    images_.clear();
    if (swapchain_) vkDestroySwapchainKHR(d, swapchain_, nullptr);
    swapchain_ = VK_NULL_HANDLE;
  }

  void remake_swapchain() {
    vkQueueWaitIdle(ctx_->queue());
    destroy_swapchain();
    make_swapchain();
    ImGui_ImplVulkan_SetMinImageCount(min_images_);
  }

  void init_imgui() {
    const std::array<VkDescriptorPoolSize, 1> sizes{{{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16}}};
    VkDescriptorPoolCreateInfo dpi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpi.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    dpi.maxSets = 16;
    dpi.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
    dpi.pPoolSizes = sizes.data();
    ENGINE_VK_CHECK(vkCreateDescriptorPool(ctx_->device(), &dpi, nullptr, &imgui_pool_));
    ImGui_ImplVulkan_InitInfo info{};
    info.Instance = ctx_->instance();
    info.PhysicalDevice = ctx_->physical_device();
    info.Device = ctx_->device();
    info.QueueFamily = ctx_->queue_family();
    info.Queue = ctx_->queue();
    info.DescriptorPool = imgui_pool_;
    info.Subpass = 0;
    info.MinImageCount = min_images_;
    info.ImageCount = static_cast<std::uint32_t>(images_.size());
    info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    info.CheckVkResultFn = check_imgui;
    if (!ImGui_ImplVulkan_Init(&info, render_pass_)) throw std::runtime_error("--backend vulkan: ImGui's Vulkan backend did not start");
    imgui_vulkan_ = true;
    // The font atlas, uploaded once.
    ENGINE_VK_CHECK(vkResetCommandBuffer(cmd_, 0));
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    ENGINE_VK_CHECK(vkBeginCommandBuffer(cmd_, &begin));
    ImGui_ImplVulkan_CreateFontsTexture(cmd_);
    ENGINE_VK_CHECK(vkEndCommandBuffer(cmd_));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd_;
    ENGINE_VK_CHECK(vkQueueSubmit(ctx_->queue(), 1, &submit, VK_NULL_HANDLE));
    ENGINE_VK_CHECK(vkQueueWaitIdle(ctx_->queue()));
    ImGui_ImplVulkan_DestroyFontUploadObjects();
  }

  // The image the game frame is copied into, then blitted from.
  void make_game_image(int width, int height) {
    vkQueueWaitIdle(ctx_->queue());
    destroy_game_image();
    game_image_ = engine::gpu::DeviceImage(*ctx_, static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height),
                                           VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    image_width_ = width;
    image_height_ = height;
  }

  void destroy_game_image() { game_image_ = engine::gpu::DeviceImage(); }

  // The window cleared, the game image scaled into the view's rectangle
  // (window coordinates to framebuffer pixels), ready for the UI pass.
  void record_view(VkImage target, const ViewRect& view, int fw, int fh) {
    transition(cmd_, target, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0, VK_ACCESS_TRANSFER_WRITE_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
    const VkClearColorValue clear{{0.08f, 0.08f, 0.09f, 1.0f}};
    const VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd_, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &clear, 1, &all);
    if (game_image_.image() && game_width_ == image_width_ && game_height_ == image_height_) {
      transition(cmd_, game_image_.image(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 0,
                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
      VkBufferImageCopy copy{};
      copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      copy.imageExtent = {static_cast<std::uint32_t>(image_width_), static_cast<std::uint32_t>(image_height_), 1};
      vkCmdCopyBufferToImage(cmd_, staging_.handle(), game_image_.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
      transition(cmd_, game_image_.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_PIPELINE_STAGE_TRANSFER_BIT);
      int ww = 0, wh = 0;
      glfwGetWindowSize(window_, &ww, &wh);
      const float sx = ww > 0 ? static_cast<float>(fw) / static_cast<float>(ww) : 1.0f;
      const float sy = wh > 0 ? static_cast<float>(fh) / static_cast<float>(wh) : 1.0f;
      const auto px = [](float v, int limit) { return std::clamp(static_cast<std::int32_t>(v + 0.5f), 0, limit); };
      VkImageBlit blit{};
      blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      blit.srcOffsets[1] = {image_width_, image_height_, 1};
      blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      blit.dstOffsets[0] = {px(view.min.x * sx, fw), px(view.min.y * sy, fh), 0};
      blit.dstOffsets[1] = {px(view.max.x * sx, fw), px(view.max.y * sy, fh), 1};
      if (blit.dstOffsets[1].x > blit.dstOffsets[0].x && blit.dstOffsets[1].y > blit.dstOffsets[0].y)
        vkCmdBlitImage(cmd_, game_image_.image(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                       &blit, VK_FILTER_LINEAR);
    }
    transition(cmd_, target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
               VK_ACCESS_TRANSFER_WRITE_BIT, VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT);
  }

  void record_ui(std::uint32_t index) {
    VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rbi.renderPass = render_pass_;
    rbi.framebuffer = framebuffers_[index];
    rbi.renderArea.extent = extent_;
    vkCmdBeginRenderPass(cmd_, &rbi, VK_SUBPASS_CONTENTS_INLINE);
    ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd_);
    vkCmdEndRenderPass(cmd_);
  }

  // The presented image copied to a host buffer (--screenshot).
  void record_read_back(VkImage image) {
    const std::size_t bytes = static_cast<std::size_t>(extent_.width) * extent_.height * 4;
    if (read_back_.size() < bytes) read_back_ = engine::gpu::GpuBuffer(*ctx_, bytes);
    transition(cmd_, image, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {extent_.width, extent_.height, 1};
    vkCmdCopyImageToBuffer(cmd_, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, read_back_.handle(), 1, &copy);
    transition(cmd_, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_ACCESS_TRANSFER_READ_BIT, 0,
               VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT);
    engine::gpu::record_memory_barrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                                       VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  }

  void write_screenshot(const std::filesystem::path& out) const {
    const int w = static_cast<int>(extent_.width), h = static_cast<int>(extent_.height);
    const auto px = read_back_.mapped_as<const std::uint8_t>(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4);
    const bool bgr = format_ == VK_FORMAT_B8G8R8A8_UNORM;
    engine::image::Rgb8Image img(w, h);
    for (std::size_t i = 0; i < static_cast<std::size_t>(w) * static_cast<std::size_t>(h); ++i) {
      img.pixels[i * 3 + 0] = px[i * 4 + (bgr ? 2 : 0)];
      img.pixels[i * 3 + 1] = px[i * 4 + 1];
      img.pixels[i * 3 + 2] = px[i * 4 + (bgr ? 0 : 2)];
    }
    engine::image::write_png(out, img);
  }

  void destroy() {
    if (ctx_) {
      vkDeviceWaitIdle(ctx_->device());
      if (imgui_vulkan_) ImGui_ImplVulkan_Shutdown();
      imgui_vulkan_ = false;
      const VkDevice d = ctx_->device();
      destroy_game_image();
      destroy_swapchain();
      staging_ = engine::gpu::GpuBuffer();
      read_back_ = engine::gpu::GpuBuffer();
      if (render_pass_) vkDestroyRenderPass(d, render_pass_, nullptr);
      if (imgui_pool_) vkDestroyDescriptorPool(d, imgui_pool_, nullptr);
      if (acquired_) vkDestroySemaphore(d, acquired_, nullptr);
      if (rendered_) vkDestroySemaphore(d, rendered_, nullptr);
      if (fence_) vkDestroyFence(d, fence_, nullptr);
      if (pool_) vkDestroyCommandPool(d, pool_, nullptr);
      render_pass_ = VK_NULL_HANDLE;
      imgui_pool_ = VK_NULL_HANDLE;
      acquired_ = rendered_ = VK_NULL_HANDLE;
      fence_ = VK_NULL_HANDLE;
      pool_ = VK_NULL_HANDLE;
      if (surface_) vkDestroySurfaceKHR(ctx_->instance(), surface_, nullptr);
      surface_ = VK_NULL_HANDLE;
    }
    if (imgui_glfw_) ImGui_ImplGlfw_Shutdown();
    imgui_glfw_ = false;
    // The kernels' users hold the context too: the session is gone before
    // the window closes (run_window), so this is the last reference.
    ctx_.reset();
    if (window_) glfwDestroyWindow(window_);
    window_ = nullptr;
  }

  GLFWwindow* window_ = nullptr;
  std::shared_ptr<engine::gpu::VulkanContext> ctx_;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{0, 0};
  std::uint32_t min_images_ = 2;
  bool can_read_back_ = false;
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkDescriptorPool imgui_pool_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  VkSemaphore acquired_ = VK_NULL_HANDLE, rendered_ = VK_NULL_HANDLE;
  engine::gpu::DeviceImage game_image_;
  int image_width_ = 0, image_height_ = 0;  // game_image_'s size
  int game_width_ = 0, game_height_ = 0;    // this frame's image's size
  engine::gpu::GpuBuffer staging_, read_back_;
  bool imgui_glfw_ = false, imgui_vulkan_ = false;
};

}  // namespace

std::unique_ptr<Presenter> make_vulkan_presenter(int width, int height, const char* title,
                                                 const InstallCallbacks& install_callbacks) {
  return std::make_unique<VulkanPresenter>(width, height, title, install_callbacks);
}

}  // namespace game
