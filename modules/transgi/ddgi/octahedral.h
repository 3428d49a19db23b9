#pragma once
// Octahedral probe maps as in NVIDIA's RTXGI DDGI: a probe's sphere of
// directions folded onto a square of `interior` x `interior` texels, with a
// one-texel border copied from the opposite edges so that bilinear filtering
// is seamless across the fold.
#include <vector>

#include <glm/glm.hpp>

namespace transgi::ddgi {

// Unit direction -> octahedral coordinates in [-1, 1]^2 (RTXGI's convention:
// +Z is the centre of the square, -Z its corners).
glm::vec2 octahedral_coordinates(const glm::vec3& direction);
// The inverse (normalised).
glm::vec3 octahedral_direction(glm::vec2 coordinates);

// One probe's map with its border: (interior + 2)^2 texels of T.
template <class T>
struct OctahedralMap {
  int interior = 6;
  std::vector<T> texels;

  explicit OctahedralMap(int n = 6, T fill = T(0)) : interior(n), texels(static_cast<std::size_t>((n + 2) * (n + 2)), fill) {}
  [[nodiscard]] int size() const { return interior + 2; }
  [[nodiscard]] T& at(int x, int y) { return texels[static_cast<std::size_t>(y * size() + x)]; }
  [[nodiscard]] const T& at(int x, int y) const { return texels[static_cast<std::size_t>(y * size() + x)]; }
};

// Direction of interior texel (x, y), x, y in [0, interior) (its centre).
glm::vec3 texel_direction(int x, int y, int interior);

// Copies the border texels from the interior (RTXGI's ProbeBorderUpdate).
template <class T>
void update_border(OctahedralMap<T>& m) {
  const int n = m.interior, e = n + 1;
  for (int i = 1; i <= n; ++i) {
    m.at(i, 0) = m.at(e - i, 1);  // top row: mirrored first row
    m.at(i, e) = m.at(e - i, n);  // bottom row: mirrored last row
    m.at(0, i) = m.at(1, e - i);  // left column: mirrored first column
    m.at(e, i) = m.at(n, e - i);  // right column: mirrored last column
  }
  m.at(0, 0) = m.at(n, n);
  m.at(e, 0) = m.at(1, n);
  m.at(0, e) = m.at(n, 1);
  m.at(e, e) = m.at(1, 1);
}

// Bilinear lookup in direction `d`, as a GPU sampler would read the atlas
// at RTXGI's DDGIGetProbeUV.
// The same at octahedral coordinates already found (octahedral_coordinates),
// for several maps looked up in one direction.
template <class T>
T sample_bilinear_at(const OctahedralMap<T>& m, const glm::vec2& oct) {
  const float half = 0.5f * static_cast<float>(m.size());
  const glm::vec2 p = glm::vec2(half) + oct * (0.5f * static_cast<float>(m.interior)) - glm::vec2(0.5f);
  const glm::vec2 c = glm::clamp(p, glm::vec2(0.0f), glm::vec2(static_cast<float>(m.size() - 1)));
  const int x0 = std::min(static_cast<int>(c.x), m.size() - 2), y0 = std::min(static_cast<int>(c.y), m.size() - 2);
  const float fx = c.x - static_cast<float>(x0), fy = c.y - static_cast<float>(y0);
  return (m.at(x0, y0) * (1 - fx) + m.at(x0 + 1, y0) * fx) * (1 - fy) + (m.at(x0, y0 + 1) * (1 - fx) + m.at(x0 + 1, y0 + 1) * fx) * fy;
}

template <class T>
T sample_bilinear(const OctahedralMap<T>& m, const glm::vec3& d) {
  return sample_bilinear_at(m, octahedral_coordinates(d));
}

}  // namespace transgi::ddgi
