#include "engine/gpu/gpu_ray_tracer.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "engine/gpu/gpu_error.h"

namespace engine::gpu {

GpuRayTracer::GpuRayTracer(VulkanContext& ctx) : ctx_(ctx), raster_(ctx.info().raster_visibility) {}

GpuRayTracer::~GpuRayTracer() = default;

void GpuRayTracer::follow(const rt::RtScene& scene) {
  if (!scene.assets()) throw GpuError("the Vulkan backend traces only scenes built with their assets (RtScene::assets())");
  if (!rt_) rt_ = std::make_unique<GpuRtScene>(ctx_);
  // Another scene, or a new commit (something moved): the TLAS follows.
  if (synced_ != &scene || commits_ != scene.stats().top_level_commits) {
    // A queued view binds the buffers the sync may replace.
    if (visibility_) visibility_->drop_queued();
    rt_->sync(scene);
    synced_ = &scene;
    commits_ = scene.stats().top_level_commits;
  }
}

void GpuRayTracer::intersect(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<rt::Hit> hits,
                             std::span<std::uint8_t> found) {
  follow(scene);
  double ms = 0;
  rt_->intersect(rays, hits, found, &ms);
  gpu_ms_ += std::max(0.0, ms);
}

void GpuRayTracer::occluded(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<std::uint8_t> blocked) {
  follow(scene);
  double ms = 0;
  rt_->occluded(rays, blocked, &ms);
  gpu_ms_ += std::max(0.0, ms);
}

void GpuRayTracer::camera_hits(const rt::RtScene& scene, const render::CameraRays& camera, glm::vec2 film_offset,
                               std::span<rt::Hit> hits, std::span<std::uint8_t> found) {
  if (!raster_) throw GpuError("GpuRayTracer::camera_hits: the device's queue does not rasterise here (camera_hit_tracer() is null)");
  follow(scene);
  if (!visibility_) visibility_ = std::make_unique<VisibilityPass>(ctx_);
  double ms = 0;
  const float near = near_plane(scene);
  if (!visibility_->take_queued(*rt_, camera, film_offset, near, hits, found, &ms))
    visibility_->render(*rt_, camera, film_offset, near, hits, found, &ms);
  gpu_ms_ += std::max(0.0, ms);
}

void GpuRayTracer::queue_camera_hits(const rt::RtScene& scene, const render::CameraRays& camera, glm::vec2 film_offset,
                                     const render::ViewShadowRequest* shadows) {
  if (!raster_ || !scene.assets()) return;
  // Only a hint: where the device cannot hold the scene, camera_hits meets
  // the same error in the frame, whose owner falls back and says why.
  try {
    follow(scene);
    if (!visibility_) visibility_ = std::make_unique<VisibilityPass>(ctx_);
    visibility_->queue(*rt_, camera, film_offset, near_plane(scene), shadows);
  } catch (const GpuError&) {
    if (visibility_) visibility_->drop_queued();
  }
}

bool GpuRayTracer::take_view_shadows(const render::ViewShadowRequest& request, std::vector<float>& answers) {
  return visibility_ && visibility_->take_shadows(request, answers);
}

float GpuRayTracer::near_plane(const rt::RtScene& scene) {
  // A camera ray starts at the eye (tmin 0); the raster needs a near plane:
  // a millionth of the scene's size, where a reversed float depth keeps
  // its precision all the same.
  const glm::vec3 extent = scene.bounds_max() - scene.bounds_min();
  const float size = std::max({extent.x, extent.y, extent.z});
  return std::isfinite(size) && size > 0 ? 1e-6f * size : 1e-6f;
}

void GpuRayTracer::set_raster_visibility(bool enabled) { raster_ = enabled && VisibilityPass::supported(ctx_); }

void GpuRayTracer::occluded_later(const rt::RtScene& scene, std::span<const rt::Ray> rays) {
  follow(scene);
  rt_->occluded_later(rays);
}

void GpuRayTracer::take_occluded(std::span<std::uint8_t> blocked) {
  if (!rt_) throw GpuError("GpuRayTracer::take_occluded: no batch queued");
  rt_->take_occluded(blocked);
}

void GpuRayTracer::distances_later(const rt::RtScene& scene, std::span<const rt::Ray> rays) {
  follow(scene);
  rt_->distances_later(rays);
}

void GpuRayTracer::take_distances(std::span<float> distances) {
  if (!rt_) throw GpuError("GpuRayTracer::take_distances: no batch queued");
  rt_->take_distances(distances);
}

double GpuRayTracer::take_device_ms() { return std::exchange(gpu_ms_, 0.0) + (rt_ ? rt_->take_deferred_ms() : 0.0); }

}  // namespace engine::gpu
