#pragma once
// rt::RayBatchTracer on a Vulkan device: a GpuRtScene that follows the
// RtScene (synced whenever its top level was committed again) and traces
// each batch in one dispatch, alpha-masked materials cut out as Embree's
// filter does. Declines only a scene without assets.
#include <memory>
#include <vector>

#include "engine/gpu/gpu_rt_scene.h"
#include "engine/rt/ray_batch_tracer.h"

namespace engine::gpu {

class GpuRayTracer : public rt::RayBatchTracer {
 public:
  explicit GpuRayTracer(VulkanContext& ctx) : ctx_(ctx) {}

  bool intersect(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<rt::Hit> hits,
                 std::span<std::uint8_t> found) override;
  // Stops each ray's traversal at its first hit.
  bool occluded(const rt::RtScene& scene, std::span<const rt::Ray> rays, std::span<std::uint8_t> blocked) override;
  // GPU milliseconds of the traces since the last call (timestamps).
  double take_device_ms() override;
  // The device's copy of `scene`, synced, for kernels that trace in their
  // own submissions (GpuRtScene::bind); null where it declines the scene.
  GpuRtScene* device_scene(const rt::RtScene& scene) { return follow(scene) ? rt_.get() : nullptr; }

 private:
  VulkanContext& ctx_;
  std::unique_ptr<GpuRtScene> rt_;
  const rt::RtScene* synced_ = nullptr;
  std::size_t commits_ = 0;
  bool follow(const rt::RtScene& scene);  // syncs when needed; false: declines the scene
  double gpu_ms_ = 0.0;
};

}  // namespace engine::gpu
