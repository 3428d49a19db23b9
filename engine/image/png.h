#pragma once
// 8-bit sRGB PNG output.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace engine::image {

struct Rgb8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // row-major RGB, top row first

  Rgb8Image() = default;
  Rgb8Image(int w, int h) : width(w), height(h), pixels(static_cast<std::size_t>(w) * h * 3, 0) {}
  std::uint8_t* at(int x, int y) { return &pixels[(static_cast<std::size_t>(y) * width + x) * 3]; }
};

// Encodes and writes atomically (temp file + rename). Throws io::IoError.
void write_png(const std::filesystem::path& path, const Rgb8Image& image);
// Reads an 8-bit PNG as RGB. Throws io::IoError naming the file.
Rgb8Image read_png(const std::filesystem::path& path);

}  // namespace engine::image
