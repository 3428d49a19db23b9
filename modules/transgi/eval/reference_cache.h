#pragma once
// The path-traced reference (full, direct and gi passes from the same
// samples), cached on disk by scene fingerprint and render settings: a
// 1024-spp reference of a real scene takes minutes, and eval / bench-pareto
// runs reuse it.
//
// It is rendered as two independent halves (two seeds) and averaged: the
// halves' difference measures the reference's own noise, which every report
// prints beside the errors it judges (an error near the noise says little).
// RMSE(a, b) / 2 estimates the RMSE of (a + b) / 2 against the converged image,
// for independent unbiased halves.
#include <filesystem>
#include <string>

#include "engine/image/image.h"
#include "eval/method_runs.h"

namespace transgi::eval {

struct ReferenceOptions {
  int spp = 1024;  // uniform: samples per pixel over both halves; adaptive: the most any pixel gets
  // > 0: adaptive sampling of the gi pass to this relative error per pixel
  // (engine::render::AdaptiveSampling), each half to sqrt(2) times it.
  float target_error = 0;
  std::uint64_t seed = 0;
};

struct ReferenceImages {
  engine::image::ImageRGB full, direct, gi;
  int spp = 0;               // as asked (ReferenceOptions::spp)
  float target_error = 0;
  double mean_spp = 0;       // samples per pixel actually taken, both halves
  double noise_gi = 0, noise_full = 0;  // estimated RMSE of gi and full against the converged images
  double seconds = 0;        // render time when it was made
  bool from_cache = false;
  std::string key;
};

ReferenceImages reference_images(LoadedScene& scene, int width, int height, const ReferenceOptions& options,
                                 const std::filesystem::path& cache_dir, bool progress = true);

// "reference noise: RMSE 0.0123 (gi), 0.0101 (full)" and, when the noise is
// above a fifth of the smallest error judged against it, a warning line.
std::string reference_noise_note(const ReferenceImages& ref, double smallest_error);

// The path tracer's gi pass at `spp` (no caching): the equal-time baseline.
engine::image::ImageRGB path_traced_gi(LoadedScene& scene, int width, int height, int spp, std::uint64_t seed, double* seconds);

}  // namespace transgi::eval
