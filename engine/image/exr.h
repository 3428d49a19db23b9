#pragma once
// OpenEXR I/O. Reading accepts only single-part, flat, scanline images (the
// version flags are checked before OpenEXR parses anything) within size caps,
// and rejects non-finite pixels. Writing goes through a temporary file.
#include <filesystem>

#include "engine/image/image.h"

namespace engine::image {

struct ExrLimits {
  int max_dimension = 32768;
  long long max_pixels = 1ll << 28;           // 268M pixels
  long long max_file_bytes = 4ll << 30;       // 4 GiB
};

enum class ExrPixelType { Float, Half };

ImageRGB read_exr(const std::filesystem::path& path, const ExrLimits& limits = {});
// Half output clamps finite values to +-65504. Non-finite pixels are refused
// (the message names the first one) rather than written silently.
void write_exr(const std::filesystem::path& path, const ImageRGB& image, ExrPixelType type = ExrPixelType::Float);

// Radiance .hdr (RGBE), through stb_image after checking the signature.
ImageRGB read_hdr(const std::filesystem::path& path, const ExrLimits& limits = {});
// Dispatches on the file's magic bytes (EXR or Radiance HDR).
ImageRGB read_hdr_image(const std::filesystem::path& path, const ExrLimits& limits = {});

}  // namespace engine::image
