#pragma once
// A backend that finds what a pinhole camera sees at every pixel somewhere
// other than Embree: a GPU's raster visibility pass (engine/gpu/
// visibility_pass). The G-buffer asks its ray tracer for one
// (rt::RayBatchTracer::camera_hit_tracer) and, where there is one, takes the
// camera's hits from it instead of tracing the camera rays.
#include <cstdint>
#include <span>
#include <vector>

#include "engine/render/camera_rays.h"
#include "engine/render/view_shadows.h"
#include "engine/rt/rt_scene.h"

namespace engine::render {

class CameraHitTracer {
 public:
  virtual ~CameraHitTracer() = default;
  // The hits of camera.generate((x, y) + film_offset) for every pixel,
  // row by row from the top-left, as RtScene::intersect gives them (a
  // rasteriser and a ray may round a pixel on an edge apart); found[i]:
  // pixel i saw a surface. Throws where it cannot (RayBatchTracer's rule).
  virtual void camera_hits(const rt::RtScene& scene, const CameraRays& camera, glm::vec2 film_offset, std::span<rt::Hit> hits,
                           std::span<std::uint8_t> found) = 0;
  // A hint that camera_hits will be asked for this view: a device starts on
  // it with its next piece of work, so that the later call costs none of
  // its own. A later call for another view (or after the scene changed)
  // is answered as if no hint had come. `shadows` (may be null): the view's
  // shadow rays to trace with it (render/view_shadows.h), for
  // take_view_shadows.
  virtual void queue_camera_hits(const rt::RtScene& /*scene*/, const CameraRays& /*camera*/, glm::vec2 /*film_offset*/,
                                 const ViewShadowRequest* /*shadows*/) {}
  // The answers of the shadow rays queued with the view the last
  // camera_hits took (trace_view_shadows' layout), where they were queued
  // for exactly `request`; false where not (none queued, the view drawn
  // anew, other lights): the caller traces its own.
  virtual bool take_view_shadows(const ViewShadowRequest& /*request*/, std::vector<float>& /*answers*/) { return false; }
};

}  // namespace engine::render
