#include "engine/gpu/gpu_ray_tracer.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "engine/gpu/gpu_error.h"

namespace engine::gpu {

GpuRayTracer::GpuRayTracer(VulkanContext& ctx) : ctx_(ctx), raster_(ctx.info().raster_visibility) {}

GpuRayTracer::~GpuRayTracer() = default;

bool GpuRayTracer::follow(const rt::RtScene& scene) {
  if (!scene.assets()) return false;
  if (!rt_) rt_ = std::make_unique<GpuRtScene>(ctx_);
  // Another scene, or a new commit (something moved): the TLAS follows.
  if (synced_ != &scene || commits_ != scene.stats().top_level_commits) {
    // A queued view binds the buffers the sync may replace.
    if (visibility_) visibility_->drop_queued();
    rt_->sync(scene);
    synced_ = &scene;
    commits_ = scene.stats().top_level_commits;
  }
  return true;
}

bool GpuRayTracer::intersect(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<rt::Hit> hits,
                             std::span<std::uint8_t> found) {
  if (!follow(scene)) return false;
  double ms = 0;
  rt_->intersect(rays, hits, found, &ms);
  gpu_ms_ += std::max(0.0, ms);
  return true;
}

bool GpuRayTracer::occluded(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<std::uint8_t> blocked) {
  if (!follow(scene)) return false;
  double ms = 0;
  rt_->occluded(rays, blocked, &ms);
  gpu_ms_ += std::max(0.0, ms);
  return true;
}

bool GpuRayTracer::camera_hits(const rt::RtScene& scene, const render::CameraRays& camera, glm::vec2 film_offset,
                               std::span<rt::Hit> hits, std::span<std::uint8_t> found) {
  if (!raster_ || !follow(scene)) return false;
  if (!visibility_) visibility_ = std::make_unique<VisibilityPass>(ctx_);
  double ms = 0;
  const float near = near_plane(scene);
  if (!visibility_->take_queued(*rt_, camera, film_offset, near, hits, found, &ms))
    visibility_->render(*rt_, camera, film_offset, near, hits, found, &ms);
  gpu_ms_ += std::max(0.0, ms);
  return true;
}

void GpuRayTracer::queue_camera_hits(const rt::RtScene& scene, const render::CameraRays& camera, glm::vec2 film_offset) {
  if (!raster_ || !follow(scene)) return;
  if (!visibility_) visibility_ = std::make_unique<VisibilityPass>(ctx_);
  visibility_->queue(*rt_, camera, film_offset, near_plane(scene));
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

bool GpuRayTracer::occluded_later(const rt::RtScene& scene, std::span<const rt::Ray> rays) {
  if (!follow(scene)) return false;
  rt_->occluded_later(rays);
  return true;
}

void GpuRayTracer::take_occluded(std::span<std::uint8_t> blocked) {
  if (!rt_) throw GpuError("GpuRayTracer::take_occluded: no batch queued");
  rt_->take_occluded(blocked);
}

double GpuRayTracer::take_device_ms() { return std::exchange(gpu_ms_, 0.0) + (rt_ ? rt_->take_deferred_ms() : 0.0); }

}  // namespace engine::gpu
