#pragma once
// The reference path tracer: unidirectional, next-event estimation with MIS
// (power heuristic) for emissive triangles, punctual lights and the
// importance-sampled environment, Russian roulette after a few bounces.
//
// It writes three passes from the same paths, defined as Cycles defines them:
//   direct = light reaching the camera-visible point straight from an emitter
//            (plus emitters and environment seen directly),
//   gi     = everything else (light that bounced at least once more),
//   full   = direct + gi (accumulated on its own, so a bucketing slip shows).
//
// Every sample's random numbers depend only on (seed, pixel, sample index),
// so images are identical for any thread count and any progressive batch size.
#include <cstdint>
#include <functional>

#include "engine/image/image.h"
#include "engine/math/rng.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_set.h"

namespace engine::render {

struct PathTracerSettings {
  // Higher = longer light paths survive, at the cost of time; Russian
  // roulette already makes long paths rare, so this is a safety cap.
  int max_depth = 64;
  // Bounce from which Russian roulette may end paths. Higher = less noise on
  // short paths, at the cost of time.
  int roulette_start = 3;
  // Pixel filter width in pixels (Blackman-Harris, as Cycles' default 1.5).
  float filter_width = 1.5f;
  std::uint64_t seed = 0;
  // Samples per pixel per progressive batch. Higher = fewer scheduling
  // rounds, at the cost of coarser progress reports. Does not change results.
  int batch_spp = 4;
};

enum class Pass { Full, Direct, Gi };

struct PathRadiance {
  glm::vec3 full{0.0f}, direct{0.0f}, gi{0.0f};
};

struct PathTracerStats {
  std::uint64_t samples = 0;
  std::uint64_t discarded_non_finite = 0;
  double seconds = 0.0;
};

class PathTracer;

// The direct pass alone (paths end after their first bounce) at `spp`
// samples per pixel: what real-time GI methods add to their indirect light.
image::ImageRGB render_direct_light(const rt::RtScene& scene, const LightSet& lights, const CameraRays& camera, int width,
                                    int height, int spp, std::uint64_t seed);

class PathTracer {
 public:
  PathTracer(const rt::RtScene& scene, const LightSet& lights, CameraRays camera, int width, int height,
             PathTracerSettings settings = {});

  // Adds spp samples per pixel (progressively); progress(done, total) after each batch.
  void render(int spp, const std::function<void(int, int)>& progress = {});
  [[nodiscard]] image::ImageRGB image(Pass pass) const;
  [[nodiscard]] int samples_per_pixel() const { return spp_; }
  [[nodiscard]] const PathTracerStats& stats() const { return stats_; }

  // One path from a camera ray (exposed for tests and other integrators).
  [[nodiscard]] PathRadiance trace(rt::Ray ray, math::Pcg32& rng) const;

 private:
  const rt::RtScene& scene_;
  const LightSet& lights_;
  CameraRays camera_;
  int width_, height_;
  PathTracerSettings settings_;
  std::vector<glm::dvec3> sum_full_, sum_direct_, sum_gi_;
  int spp_ = 0;
  PathTracerStats stats_;
};

const char* pass_name(Pass p);

}  // namespace engine::render
