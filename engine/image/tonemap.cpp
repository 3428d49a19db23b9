#include "engine/image/tonemap.h"

#include <algorithm>
#include <cmath>

namespace engine::image {

float linear_to_srgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

float srgb_to_linear(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

Rgb8Image to_srgb8(const ImageRGB& linear, float exposure_stops) {
  Rgb8Image out(linear.width, linear.height);
  const float scale = std::exp2(exposure_stops);
  for (std::size_t i = 0; i < linear.pixels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = linear.pixels[i][c];
      const float e = std::isfinite(v) ? linear_to_srgb(v * scale) : 0.0f;
      out.pixels[i * 3 + static_cast<std::size_t>(c)] = static_cast<std::uint8_t>(std::lround(e * 255.0f));
    }
  return out;
}

void write_png_srgb(const std::filesystem::path& path, const ImageRGB& linear, float exposure_stops) {
  write_png(path, to_srgb8(linear, exposure_stops));
}

}  // namespace engine::image
