#pragma once
// Linear float RGB image, row-major, top row first.
#include <cstddef>
#include <stdexcept>
#include <vector>

#include <glm/glm.hpp>

namespace engine::image {

// Any failure to read, validate or write an image. The message names the
// file and, where there is one, the offending field or pixel.
class ImageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ImageRGB {
  int width = 0;
  int height = 0;
  std::vector<glm::vec3> pixels;

  ImageRGB() = default;
  ImageRGB(int w, int h, glm::vec3 fill = glm::vec3(0.0f))
      : width(w), height(h), pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), fill) {}

  [[nodiscard]] glm::vec3& at(int x, int y) { return pixels[static_cast<std::size_t>(y) * width + x]; }
  [[nodiscard]] const glm::vec3& at(int x, int y) const { return pixels[static_cast<std::size_t>(y) * width + x]; }
  [[nodiscard]] std::size_t size() const { return pixels.size(); }
  [[nodiscard]] bool empty() const { return pixels.empty(); }
};

}  // namespace engine::image
