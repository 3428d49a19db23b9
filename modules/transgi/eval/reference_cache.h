#pragma once
// The path-traced reference (full, direct and gi passes from the same
// samples), cached on disk by scene fingerprint and render settings: a
// 1024-spp reference of a real scene takes minutes, and eval / bench-pareto
// runs reuse it.
#include <filesystem>
#include <string>

#include "engine/image/image.h"
#include "eval/method_runs.h"

namespace transgi::eval {

struct ReferenceImages {
  engine::image::ImageRGB full, direct, gi;
  int spp = 0;
  double seconds = 0;        // render time when it was made
  bool from_cache = false;
  std::string key;
};

ReferenceImages reference_images(LoadedScene& scene, int width, int height, int spp, std::uint64_t seed,
                                 const std::filesystem::path& cache_dir, bool progress = true);

// The path tracer's gi pass at `spp` (no caching): the equal-time baseline.
engine::image::ImageRGB path_traced_gi(LoadedScene& scene, int width, int height, int spp, std::uint64_t seed, double* seconds);

}  // namespace transgi::eval
