#include "engine/scene/texture.h"

#include <array>
#include <cmath>

namespace engine::scene {

namespace {

const std::array<float, 256>& srgb_lut() {
  static const std::array<float, 256> lut = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const float v = static_cast<float>(i) / 255.0f;
      t[static_cast<std::size_t>(i)] = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
    }
    return t;
  }();
  return lut;
}

int wrap_index(int i, int n, Wrap mode) {
  switch (mode) {
    case Wrap::ClampToEdge:
      return i < 0 ? 0 : (i >= n ? n - 1 : i);
    case Wrap::MirroredRepeat: {
      const int period = 2 * n;
      int m = i % period;
      if (m < 0) m += period;
      return m < n ? m : period - 1 - m;
    }
    case Wrap::Repeat:
    default: {
      int m = i % n;
      return m < 0 ? m + n : m;
    }
  }
}

}  // namespace

glm::vec4 Texture::sample(glm::vec2 uv, bool srgb) const {
  if (width <= 0 || height <= 0) return glm::vec4(1.0f);
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) uv = glm::vec2(0.0f);
  // Keep the coordinate small before flooring so huge UVs stay exact enough.
  const float x = std::fmod(uv.x, 4096.0f) * static_cast<float>(width) - 0.5f;
  const float y = std::fmod(uv.y, 4096.0f) * static_cast<float>(height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const auto& lut = srgb_lut();
  auto texel = [&](int xi, int yi) {
    const int cx = wrap_index(xi, width, wrap_s), cy = wrap_index(yi, height, wrap_t);
    const std::uint8_t* p = &rgba[(static_cast<std::size_t>(cy) * width + cx) * 4];
    if (srgb) return glm::vec4(lut[p[0]], lut[p[1]], lut[p[2]], static_cast<float>(p[3]) / 255.0f);
    return glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f;
  };
  const glm::vec4 a = texel(x0, y0), b = texel(x0 + 1, y0), c = texel(x0, y0 + 1), d = texel(x0 + 1, y0 + 1);
  return (1 - ty) * ((1 - tx) * a + tx * b) + ty * ((1 - tx) * c + tx * d);
}

float Texture::alpha_nearest(glm::vec2 uv) const {
  if (width <= 0 || height <= 0) return 1.0f;
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return 1.0f;
  const int x = static_cast<int>(std::floor(std::fmod(uv.x, 4096.0f) * static_cast<float>(width)));
  const int y = static_cast<int>(std::floor(std::fmod(uv.y, 4096.0f) * static_cast<float>(height)));
  const int cx = wrap_index(x, width, wrap_s), cy = wrap_index(y, height, wrap_t);
  return static_cast<float>(rgba[(static_cast<std::size_t>(cy) * width + cx) * 4 + 3]) / 255.0f;
}

}  // namespace engine::scene
