#include "engine/render/temporal_accumulation.h"

#include <cstring>

#include "engine/core/fnv1a.h"

namespace engine::render {

std::uint64_t view_key(const transform::Similarity& camera, int width, int height, std::uint64_t geometry_version,
                       std::uint64_t lights_version) {
  core::Fnv1a h;
  const float pose[8] = {camera.translation.x, camera.translation.y, camera.translation.z, camera.rotation.w,
                         camera.rotation.x,    camera.rotation.y,    camera.rotation.z,    camera.scale};
  for (float f : pose) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &f, sizeof bits);
    h.value(bits);
  }
  for (std::uint64_t v : {static_cast<std::uint64_t>(width), static_cast<std::uint64_t>(height), geometry_version, lights_version})
    h.value(v);
  return h.h;
}

const image::ImageRGB& accumulate(TemporalAccumulation& a, const image::ImageRGB& frame, std::uint64_t key, int window) {
  if (window <= 1) {
    a.frames = 0;
    a.average = frame;
    return a.average;
  }
  if (a.frames == 0 || key != a.key || a.average.width != frame.width || a.average.height != frame.height) {
    a.average = frame;
    a.frames = 1;
    a.key = key;
    return a.average;
  }
  a.frames = std::min(a.frames + 1, window);
  const float w = 1.0f / static_cast<float>(a.frames);
  for (std::size_t i = 0; i < frame.pixels.size(); ++i) a.average.pixels[i] += w * (frame.pixels[i] - a.average.pixels[i]);
  return a.average;
}

}  // namespace engine::render
