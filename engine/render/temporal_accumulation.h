#pragma once
// Accumulating jittered one-sample frames while nothing the image depends on
// changes (a still camera, geometry and lights): an antialiased image for
// the price of one sample per pixel per frame, as temporal antialiasing does
// for a still view (no reprojection: any change restarts it).
#include <cstdint>

#include "engine/image/image.h"
#include "engine/transform/transform.h"

namespace engine::render {

struct TemporalAccumulation {
  image::ImageRGB average;
  int frames = 0;
  std::uint64_t key = 0;
};

// What a still view depends on: the camera's pose, the image size and the
// scene's versions (geometry, lights).
std::uint64_t view_key(const transform::Similarity& camera, int width, int height, std::uint64_t geometry_version,
                       std::uint64_t lights_version);

// Blends `frame` into the history (an exponential window of `window` frames:
// the plain mean of the first `window`, then weight 1 / window) when `key`
// is unchanged, else restarts from it. window <= 1 returns `frame`.
const image::ImageRGB& accumulate(TemporalAccumulation& history, const image::ImageRGB& frame, std::uint64_t key, int window);

}  // namespace engine::render
