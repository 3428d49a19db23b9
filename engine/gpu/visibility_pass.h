#pragma once
// Primary visibility the way engines rasterise it: a visibility buffer
// (Burns and Hunt, "The Visibility Buffer", JCGT 2013). A raster pipeline
// draws every live instance of the GpuRtScene (its triangles pulled from the
// scene's triangle buffer by vertex index, no vertex buffers) with a depth
// test and writes, per pixel, which instance and triangle cover it; a
// compute pass then meets each pixel's camera ray with that triangle and
// writes its hit (VisibilityHitGpu: rt_query.comp's HitGpu less the mesh,
// which the instance names, and the padding), so the stages after the
// G-buffer read the raster's hits and the ray tracer's alike.
//
// Every pixel is sampled at the same film offset (a rasteriser samples one
// point per pixel; a jitter per frame moves them all), where the CPU's
// G-buffer may jitter each pixel on its own. Cut-outs (glTF MASK) are
// tested at the fragment as RtScene tests a ray's hit. Draws every triangle
// two-sided, as the ray tracer sees them. The queue must support graphics
// (supported()).
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <vulkan/vulkan_core.h>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/device_image.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/render/camera_rays.h"
#include "engine/render/view_shadows.h"
#include "engine/rt/ray.h"

namespace engine::gpu {

class GpuRtScene;
class VulkanContext;

class VisibilityPass {
 public:
  // False, with *why, where the context's queue cannot rasterise.
  static bool supported(const VulkanContext& ctx, std::string* why = nullptr);

  explicit VisibilityPass(VulkanContext& ctx);
  ~VisibilityPass();
  VisibilityPass(const VisibilityPass&) = delete;
  VisibilityPass& operator=(const VisibilityPass&) = delete;

  // Sizes the targets for `camera` and binds `scene` as of its last sync;
  // call before record() whenever either changed. `sample`: the film offset
  // inside each pixel, in [0, 1)^2 ((0.5, 0.5) is the centre). `near_plane`:
  // nothing closer to the camera is drawn (scene::Camera::znear).
  void prepare(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane);
  // Records the draw, the visibility buffer's copy and the resolve into
  // `cmd`: after it, hits_on_device() holds width x height VisibilityHitGpu, row by
  // row from the top-left.
  void record(VkCommandBuffer cmd) const;
  [[nodiscard]] const GpuBuffer& hits_on_device() const { return hits_; }

  // prepare, record in a submission of its own, and the hits read back as
  // GpuRtScene::intersect gives them (found[i]: pixel i saw a surface);
  // *gpu_ms: the submission's device time.
  void render(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane,
              std::span<rt::Hit> hits, std::span<std::uint8_t> found, double* gpu_ms = nullptr);
  // prepare, and the pass queued at the head of the device's next
  // submission (VulkanContext::record_before_next), whichever stage makes
  // it: a frame draws its camera's view with its first submission. With
  // `shadows` (lights to test), the view's shadow rays
  // (shaders/view_shadows.comp) are traced right after the resolve, in the
  // same commands.
  void queue(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane,
             const render::ViewShadowRequest* shadows = nullptr);
  // The queued pass's hits, as render() gives them, where it was queued for
  // this scene, camera, sample and near plane (submitted now if no stage
  // has yet); false, and the queued pass dropped, where it was not.
  // *gpu_ms: its device time. Its shadow rays' answers, if it had any, are
  // kept for take_shadows.
  bool take_queued(const GpuRtScene& scene, const render::CameraRays& camera, glm::vec2 sample, float near_plane,
                   std::span<rt::Hit> hits, std::span<std::uint8_t> found, double* gpu_ms = nullptr);
  // The shadow rays' answers of the view take_queued last took
  // (render::ViewShadowRequest's layout: lights x pixels), copied into
  // `answers`, where they were queued for exactly `request`; false
  // otherwise (none, or for other lights or another pattern). Each view's
  // answers are taken once.
  bool take_shadows(const render::ViewShadowRequest& request, std::vector<float>& answers);
  // Drops a queued pass that has not run (its scene is about to change).
  void drop_queued();

 private:
  void make_targets(std::uint32_t width, std::uint32_t height);
  // The push constants for this view, as prepare writes them.
  static std::vector<std::uint8_t> push_for(const render::CameraRays& camera, glm::vec2 sample, float near_plane);
  // The hits in hits_ as GpuRtScene::intersect gives them.
  void read_hits(const GpuRtScene& scene, std::span<rt::Hit> hits, std::span<std::uint8_t> found) const;
  void destroy_targets();
  // The shadow kernel's lights and answers for this view (after prepare);
  // record() then dispatches it after the resolve.
  void prepare_shadows(const GpuRtScene& scene, const render::ViewShadowRequest& request);

  VulkanContext& ctx_;
  const GpuRtScene* scene_ = nullptr;
  std::uint32_t width_ = 0, height_ = 0;
  std::vector<std::uint8_t> push_;  // VisibilityPushGpu
  // What the queued pass (queue) was prepared for; null scene: none queued.
  const GpuRtScene* queued_scene_ = nullptr;
  std::vector<std::uint8_t> queued_push_;
  // The raster pipeline: its set binds rt_traversal.glsl's eight buffers.
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  VkShaderModule vertex_ = VK_NULL_HANDLE, fragment_ = VK_NULL_HANDLE;
  // The targets: instance + 1 and triangle per pixel, and reversed depth.
  DeviceImage visibility_image_, depth_image_;
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
  GpuBuffer visibility_, hits_;
  std::unique_ptr<ComputePipeline> resolve_;
  // The view's shadow rays: made on the first queue that asks for them,
  // compiled for the device's traversal (GpuRtScene::shader_defines).
  std::unique_ptr<ComputePipeline> shadows_;
  GpuBuffer shadow_lights_, shadow_answers_;
  std::vector<std::uint8_t> shadow_push_;  // VisibilityPushGpu then ViewShadowPushGpu; empty: none this view
  std::optional<render::ViewShadowRequest> queued_shadows_, taken_shadows_;
};

}  // namespace engine::gpu
