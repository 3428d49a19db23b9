#include "engine/gpu/gpu_ray_tracer.h"

#include <algorithm>
#include <utility>

namespace engine::gpu {

bool GpuRayTracer::follow(const rt::RtScene& scene) {
  if (!scene.assets()) return false;
  if (!rt_) rt_ = std::make_unique<GpuRtScene>(ctx_);
  // Another scene, or a new commit (something moved): the TLAS follows.
  if (synced_ != &scene || commits_ != scene.stats().top_level_commits) {
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

double GpuRayTracer::take_device_ms() { return std::exchange(gpu_ms_, 0.0); }

}  // namespace engine::gpu
