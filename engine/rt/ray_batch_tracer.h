#pragma once
// A backend that traces a batch of rays against an RtScene somewhere other
// than Embree (engine/gpu/gpu_ray_tracer: a BVH in a compute shader or ray
// queries). A caller that holds one traces a frame's rays through it, in one
// call; one that holds none (the CPU backend) asks the RtScene. A tracer
// never declines a batch it was given: where it cannot trace (a device that
// cannot hold the scene, or a scene without its assets) it throws, and its
// owner runs the frame on the CPU backend whole.
#include <cstdint>
#include <span>

#include "engine/rt/rt_scene.h"

namespace engine::render {
class CameraHitTracer;
}

namespace engine::rt {

class RayBatchTracer {
 public:
  virtual ~RayBatchTracer() = default;
  // Closest hits of `rays` in `scene` as it is now; found[i] says whether ray
  // i hit, and a hit carries what RtScene::intersect's does (entity,
  // instance, mesh, primitive, barycentrics, t).
  virtual void intersect(const RtScene& scene, std::span<const Ray> rays, std::span<Hit> hits, std::span<std::uint8_t> found) = 0;
  // Shadow rays: blocked[i] = whether anything lies on ray i within
  // (tmin, tmax].
  virtual void occluded(const RtScene& scene, std::span<const Ray> rays, std::span<std::uint8_t> blocked) = 0;
  // Shadow rays whose answers the caller reads later (take_occluded),
  // traced along with the backend's next piece of work instead of on their
  // own (a device's next submission); one batch at a time.
  virtual void occluded_later(const RtScene& scene, std::span<const Ray> rays) = 0;
  // blocked[i] for ray i of the batch occluded_later queued.
  virtual void take_occluded(std::span<std::uint8_t> blocked) = 0;
  // The closest hits' distances the same way (a batch of their own,
  // beside occluded_later's), read by take_distances: +infinity where a ray
  // hits nothing up to its tmax.
  virtual void distances_later(const RtScene& scene, std::span<const Ray> rays) = 0;
  virtual void take_distances(std::span<float> distances) = 0;
  // Device milliseconds the traces took since the last call (0 where the
  // backend cannot time them), so each stage that traces can take its own.
  virtual double take_device_ms() { return 0.0; }
  // The same backend's way to see a camera's pixels without tracing their
  // rays (a raster pass), or null where it has none.
  virtual render::CameraHitTracer* camera_hit_tracer() { return nullptr; }
};

}  // namespace engine::rt
