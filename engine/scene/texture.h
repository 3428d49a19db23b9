#pragma once
// 8-bit RGBA texture with glTF sampler wrap modes and bilinear filtering.
// Colour textures are decoded from sRGB before filtering.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace engine::scene {

enum class Wrap : std::uint8_t { Repeat, ClampToEdge, MirroredRepeat };

struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // row-major, top row first (glTF v = 0 is the top)
  Wrap wrap_s = Wrap::Repeat;
  Wrap wrap_t = Wrap::Repeat;

  // Bilinear lookup; srgb = true converts each texel to linear first.
  [[nodiscard]] glm::vec4 sample(glm::vec2 uv, bool srgb) const;
  // Nearest-texel alpha (alpha testing must not blur the cut-out edge).
  [[nodiscard]] float alpha_nearest(glm::vec2 uv) const;
};

}  // namespace engine::scene
