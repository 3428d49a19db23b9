#include "engine/scene/texture.h"

#include <algorithm>
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

std::uint8_t encode_srgb(float v) {
  v = std::clamp(v, 0.0f, 1.0f);
  const float e = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
  return static_cast<std::uint8_t>(std::lround(e * 255.0f));
}

glm::vec4 bilinear(const std::uint8_t* rgba, int width, int height, Wrap wrap_s, Wrap wrap_t, glm::vec2 uv, bool srgb,
                    bool cut_out);

}  // namespace

const float* srgb_decode_table() { return srgb_lut().data(); }

glm::vec4 Texture::sample(glm::vec2 uv, bool srgb) const {
  if (width <= 0 || height <= 0) return glm::vec4(1.0f);
  return bilinear(rgba.data(), width, height, wrap_s, wrap_t, uv, srgb, cut_out);
}

glm::vec4 Texture::sample(glm::vec2 uv, bool srgb, float lod) const {
  if (width <= 0 || height <= 0) return glm::vec4(1.0f);
  if (!(lod > 0) || mips.empty()) return sample(uv, srgb);
  lod = std::min(lod, static_cast<float>(mips.size()));
  const int lo = static_cast<int>(std::floor(lod));
  const float t = lod - static_cast<float>(lo);
  auto level = [&](int l) {
    if (l == 0) return bilinear(rgba.data(), width, height, wrap_s, wrap_t, uv, srgb, cut_out);
    const MipLevel& m = mips[static_cast<std::size_t>(l - 1)];
    return bilinear(m.rgba.data(), m.width, m.height, wrap_s, wrap_t, uv, srgb, cut_out);
  };
  const glm::vec4 a = level(lo);
  if (t <= 0 || lo >= static_cast<int>(mips.size())) return a;
  return (1 - t) * a + t * level(lo + 1);
}

void Texture::build_mips(bool srgb, bool cut_out_colour) {
  cut_out = cut_out_colour;
  mips.clear();
  if (width <= 0 || height <= 0) return;
  const auto& lut = srgb_lut();
  const std::uint8_t* src = rgba.data();
  int w = width, h = height;
  while (w > 1 || h > 1) {
    MipLevel m;
    m.width = std::max(1, (w + 1) / 2);
    m.height = std::max(1, (h + 1) / 2);
    m.rgba.resize(static_cast<std::size_t>(m.width) * m.height * 4);
    for (int y = 0; y < m.height; ++y)
      for (int x = 0; x < m.width; ++x) {
        // The plain sums, and for a cut-out the alpha-weighted colour.
        float sum[4] = {0, 0, 0, 0}, weighted[3] = {0, 0, 0};
        int n = 0;
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx) {
            const int sx = std::min(2 * x + dx, w - 1), sy = std::min(2 * y + dy, h - 1);
            const std::uint8_t* p = src + (static_cast<std::size_t>(sy) * w + sx) * 4;
            const float alpha = static_cast<float>(p[3]) / 255.0f;
            for (int c = 0; c < 3; ++c) {
              const float v = srgb ? lut[p[c]] : static_cast<float>(p[c]) / 255.0f;
              sum[c] += v;
              weighted[c] += alpha * v;
            }
            sum[3] += alpha;
            ++n;
          }
        // A block with no opaque texel keeps the plain mean of its colours.
        const bool by_alpha = cut_out && sum[3] > 0;
        std::uint8_t* d = &m.rgba[(static_cast<std::size_t>(y) * m.width + x) * 4];
        for (int c = 0; c < 3; ++c) {
          const float v = by_alpha ? weighted[c] / sum[3] : sum[c] / static_cast<float>(n);
          d[c] = srgb ? encode_srgb(v) : static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
        }
        d[3] = static_cast<std::uint8_t>(std::lround(std::clamp(sum[3] / static_cast<float>(n), 0.0f, 1.0f) * 255.0f));
      }
    mips.push_back(std::move(m));
    src = mips.back().rgba.data();
    w = mips.back().width;
    h = mips.back().height;
  }
}

namespace {

glm::vec4 bilinear(const std::uint8_t* rgba, int width, int height, Wrap wrap_s, Wrap wrap_t, glm::vec2 uv, bool srgb,
                    bool cut_out) {
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
    const std::uint8_t* p = rgba + (static_cast<std::size_t>(cy) * width + cx) * 4;
    if (srgb) return glm::vec4(lut[p[0]], lut[p[1]], lut[p[2]], static_cast<float>(p[3]) / 255.0f);
    return glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f;
  };
  const glm::vec4 a = texel(x0, y0), b = texel(x0 + 1, y0), c = texel(x0, y0 + 1), d = texel(x0 + 1, y0 + 1);
  const glm::vec4 mean = (1 - ty) * ((1 - tx) * a + tx * b) + ty * ((1 - tx) * c + tx * d);
  if (!cut_out || !(mean.a > 0)) return mean;
  // A cut-out's colour weighted by alpha (as its mips are): a leaf's edge
  // does not take the colour of the transparent texels beside it.
  const glm::vec3 weighted = (1 - ty) * ((1 - tx) * a.a * glm::vec3(a) + tx * b.a * glm::vec3(b)) +
                             ty * ((1 - tx) * c.a * glm::vec3(c) + tx * d.a * glm::vec3(d));
  return glm::vec4(weighted / mean.a, mean.a);
}

}  // namespace

float Texture::alpha_nearest(glm::vec2 uv) const {
  if (width <= 0 || height <= 0) return 1.0f;
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return 1.0f;
  const int x = static_cast<int>(std::floor(std::fmod(uv.x, 4096.0f) * static_cast<float>(width)));
  const int y = static_cast<int>(std::floor(std::fmod(uv.y, 4096.0f) * static_cast<float>(height)));
  const int cx = wrap_index(x, width, wrap_s), cy = wrap_index(y, height, wrap_t);
  return static_cast<float>(rgba[(static_cast<std::size_t>(cy) * width + cx) * 4 + 3]) / 255.0f;
}

}  // namespace engine::scene
