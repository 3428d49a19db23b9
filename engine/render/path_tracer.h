#pragma once
// The reference path tracer: unidirectional, next-event estimation with MIS
// (power heuristic) for emissive triangles, punctual lights and the
// importance-sampled environment, Russian roulette after a few bounces.
//
// It writes three passes from the same paths, defined as Cycles defines them:
//   direct = light reaching the camera-visible point straight from an emitter
//            (plus emitters and environment seen directly),
//   gi     = everything else (light that bounced at least once more),
//   full   = direct + gi (accumulated on its own, so a bucketing slip shows),
// and an albedo pass: the base colour (texture included) of the first surface a
// camera ray meets, black where it sees the background, antialiased by the same
// pixel filter (Cycles' "diffuse colour"), and a textured pass: the fraction of
// a pixel's camera rays whose first surface is textured or coloured
// (Material::is_textured_or_coloured), where colour metrics are taken.
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

enum class Pass { Full, Direct, Gi, Albedo, Textured };

// Adaptive sampling (as production renderers do): after `min_spp`, rounds of
// `round_spp` more samples go only to the pixels whose estimated relative
// error in one pass is above the target, until every pixel meets it or has
// `max_spp`. A pixel's relative error is the standard error of its mean
// luminance over max(its mean, `floor` x the image's mean): dark pixels are
// judged against the image's level, not their own near-zero value.
struct AdaptiveSampling {
  // Lower = a more converged image, at the cost of time (halving it costs about 4x).
  float target_error = 0.02f;
  int min_spp = 64;
  // Higher = pixels with rare bright paths converge too, at the cost of time there.
  int max_spp = 16384;
  int round_spp = 32;
  float floor = 1.0f;
  Pass pass = Pass::Gi;
};

struct PathRadiance {
  glm::vec3 full{0.0f}, direct{0.0f}, gi{0.0f};
  glm::vec3 albedo{0.0f};  // the first surface's base colour
  float textured = 0.0f;   // 1: the first surface is textured or coloured
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
  // Adaptive sampling (see AdaptiveSampling); progress(pixels done, pixels)
  // after each round. The rounds' choices depend only on the samples, so the
  // image is still the same for any thread count.
  void render_adaptive(const AdaptiveSampling& settings, const std::function<void(int, int)>& progress = {});
  [[nodiscard]] image::ImageRGB image(Pass pass) const;
  // Samples every pixel got (the uniform part), and the mean over pixels.
  [[nodiscard]] int samples_per_pixel() const { return spp_; }
  [[nodiscard]] double mean_samples_per_pixel() const;
  [[nodiscard]] const PathTracerStats& stats() const { return stats_; }

  // One path from a camera ray (exposed for tests and other integrators).
  [[nodiscard]] PathRadiance trace(rt::Ray ray, math::Pcg32& rng) const;

 private:
  const rt::RtScene& scene_;
  const LightSet& lights_;
  CameraRays camera_;
  int width_, height_;
  PathTracerSettings settings_;
  // Adds samples [count_[p], count_[p] + n) to each pixel p with want[p] (all if empty).
  void add_samples(int n, const std::vector<std::uint8_t>& want);

  std::vector<glm::dvec3> sum_full_, sum_direct_, sum_gi_, sum_albedo_;
  std::vector<double> sum_textured_;
  std::vector<double> sum_sq_full_, sum_sq_direct_, sum_sq_gi_;  // of luminance, for adaptive sampling
  std::vector<std::uint32_t> count_;                              // samples per pixel
  int spp_ = 0;
  PathTracerStats stats_;
};

const char* pass_name(Pass p);

}  // namespace engine::render
