#pragma once
// 8-bit RGBA texture with glTF sampler wrap modes, bilinear filtering and a
// mip chain for trilinear lookups by footprint (what rasterisers sample, so a
// one-sample G-buffer sees a wallpaper's average, not a texel pattern).
// Colour textures are decoded from sRGB before filtering.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace engine::scene {

enum class Wrap : std::uint8_t { Repeat, ClampToEdge, MirroredRepeat };

// The linear value of each sRGB-encoded byte, as sample() decodes texels.
const float* srgb_decode_table();  // 256 entries

struct MipLevel {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
};

struct Texture {
  std::string name;
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // row-major, top row first (glTF v = 0 is the top)
  Wrap wrap_s = Wrap::Repeat;
  Wrap wrap_t = Wrap::Repeat;
  // Levels 1, 2, ... down to 1 x 1 (level 0 is rgba); empty until build_mips.
  std::vector<MipLevel> mips;
  // The colour of an alpha-tested texture (build_mips' cut_out): lookups
  // weight each texel's colour by its alpha.
  bool cut_out = false;

  // Bilinear lookup; srgb = true converts each texel to linear first.
  [[nodiscard]] glm::vec4 sample(glm::vec2 uv, bool srgb) const;
  // Trilinear lookup at level of detail `lod` (log2 of the footprint in
  // level-0 texels); lod <= 0 or no mips = the bilinear lookup.
  [[nodiscard]] glm::vec4 sample(glm::vec2 uv, bool srgb, float lod) const;
  // 2 x 2 box-filtered levels. srgb = average in linear light and store
  // sRGB-encoded (a black and white checker averages to 0.5 linear, not to
  // 0.5 encoded, which is 0.21 linear). cut_out_colour = the colour is averaged
  // weighted by alpha (an alpha-tested leaf's colour, not the transparent
  // texels' around it: their RGB, often white, turned plants pale at a
  // distance), here and in every lookup after (sets cut_out); alpha itself
  // is averaged plainly.
  void build_mips(bool srgb, bool cut_out_colour = false);
  // Nearest-texel alpha (alpha testing must not blur the cut-out edge).
  [[nodiscard]] float alpha_nearest(glm::vec2 uv) const;
};

}  // namespace engine::scene
