#pragma once
// rt::RayBatchTracer on a Vulkan device: a GpuRtScene that follows the
// RtScene (synced whenever its top level was committed again) and traces
// each batch in one dispatch, alpha-masked materials cut out as Embree's
// filter does; and a camera's hits from a raster visibility pass where the
// device's queue can rasterise. Throws GpuError for a scene without its
// assets, as for one the device cannot hold.
#include <memory>
#include <vector>

#include "engine/gpu/gpu_rt_scene.h"
#include "engine/gpu/visibility_pass.h"
#include "engine/render/camera_hit_tracer.h"
#include "engine/rt/ray_batch_tracer.h"

namespace engine::gpu {

class GpuRayTracer : public rt::RayBatchTracer, public render::CameraHitTracer {
 public:
  explicit GpuRayTracer(VulkanContext& ctx);
  ~GpuRayTracer() override;

  void intersect(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<rt::Hit> hits,
                 std::span<std::uint8_t> found) override;
  // Stops each ray's traversal at its first hit.
  void occluded(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<std::uint8_t> blocked) override;
  // Queued at the head of the device's next submission (GpuRtScene::
  // occluded_later).
  void occluded_later(const rt::RtScene& scene, std::span<const rt::Ray> rays) override;
  void take_occluded(std::span<std::uint8_t> blocked) override;
  void distances_later(const rt::RtScene& scene, std::span<const rt::Ray> rays) override;
  void take_distances(std::span<float> distances) override;
  // GPU milliseconds of the traces since the last call (timestamps),
  // the TLAS's rebuilds and the later batches with them.
  double take_device_ms() override;
  // The raster visibility pass (VisibilityPass) where the device's options
  // ask for it (DeviceInfo::raster_visibility) or set_raster_visibility
  // did; else null, and the camera's rays are traced.
  render::CameraHitTracer* camera_hit_tracer() override { return raster_ ? this : nullptr; }
  void camera_hits(const rt::RtScene& scene, const render::CameraRays& camera, glm::vec2 film_offset, std::span<rt::Hit> hits,
                   std::span<std::uint8_t> found) override;
  // The view's visibility pass queued at the head of the device's next
  // submission (VisibilityPass::queue); camera_hits takes it when it asks
  // for the same view of the same scene.
  // With `shadows`, the view's shadow rays are traced right after it
  // (VisibilityPass::queue).
  void queue_camera_hits(const rt::RtScene& scene, const render::CameraRays& camera, glm::vec2 film_offset,
                         const render::ViewShadowRequest* shadows) override;
  bool take_view_shadows(const render::ViewShadowRequest& request, std::vector<float>& answers) override;
  // Whether the G-buffer takes its hits from the raster pass, where the
  // queue can rasterise, whatever the device's options say: a test or a
  // benchmark compares the two.
  void set_raster_visibility(bool enabled);
  // The device's copy of `scene`, synced, for kernels that trace in their
  // own submissions (GpuRtScene::bind).
  GpuRtScene* device_scene(const rt::RtScene& scene) {
    follow(scene);
    return rt_.get();
  }

 private:
  VulkanContext& ctx_;
  std::unique_ptr<GpuRtScene> rt_;
  std::unique_ptr<VisibilityPass> visibility_;  // made on the first camera_hits
  bool raster_ = false;
  const rt::RtScene* synced_ = nullptr;
  std::size_t commits_ = 0;
  // Syncs when needed; throws GpuError for a scene without its assets
  // (nothing to upload).
  void follow(const rt::RtScene& scene);
  // The raster's near plane for `scene`.
  static float near_plane(const rt::RtScene& scene);
  double gpu_ms_ = 0.0;
};

}  // namespace engine::gpu
