#pragma once
// Display encoding: exposure (in stops), clamp to [0, 1], sRGB transfer.
#include <filesystem>

#include "engine/image/image.h"
#include "engine/image/png.h"

namespace engine::image {

float linear_to_srgb(float linear);
float srgb_to_linear(float encoded);
Rgb8Image to_srgb8(const ImageRGB& linear, float exposure_stops = 0.0f);
void write_png_srgb(const std::filesystem::path& path, const ImageRGB& linear, float exposure_stops = 0.0f);

}  // namespace engine::image
