#pragma once
// A backend that traces a batch of rays against an RtScene somewhere other
// than Embree (engine/gpu/gpu_ray_tracer: a BVH in a compute shader). Callers
// that hold one trace a frame's rays in one call and fall back to the
// RtScene's own queries when it declines.
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
  // instance, mesh, primitive, barycentrics, t). Returns false, touching
  // nothing, where this backend cannot trace the scene exactly.
  virtual bool intersect(const RtScene& scene, std::span<const Ray> rays, std::span<Hit> hits,
                         std::span<std::uint8_t> found) = 0;
  // Shadow rays: blocked[i] = whether anything lies on ray i within
  // (tmin, tmax]. Returns false, touching nothing, where it declines.
  virtual bool occluded(const RtScene& scene, std::span<const Ray> rays, std::span<std::uint8_t> blocked) = 0;
  // Shadow rays whose answers the caller reads later (take_occluded),
  // traced along with the backend's next piece of work instead of on their
  // own (a device's next submission). Returns false, queuing nothing, where
  // the backend declines; one batch at a time.
  virtual bool occluded_later(const RtScene& /*scene*/, std::span<const Ray> /*rays*/) { return false; }
  // blocked[i] for ray i of the batch occluded_later queued.
  virtual void take_occluded(std::span<std::uint8_t> /*blocked*/) {}
  // Device milliseconds the traces took since the last call (0 where the
  // backend cannot time them), so each stage that traces can take its own.
  virtual double take_device_ms() { return 0.0; }
  // The same backend's way to see a camera's pixels without tracing their
  // rays (a raster pass), or null where it has none.
  virtual render::CameraHitTracer* camera_hit_tracer() { return nullptr; }
};

}  // namespace engine::rt
