#include "probes/probe_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace transgi::probes {

float ProbeGrid::min_spacing() const {
  const glm::vec3 s = spacing();
  float m = std::numeric_limits<float>::infinity();
  for (int a = 0; a < 3; ++a)
    if (dims[a] > 1 && s[a] > 0) m = std::min(m, s[a]);
  return std::isfinite(m) ? m : 1.0f;
}

void ProbeGrid::scroll_by(glm::ivec3 cells) {
  const glm::vec3 shift = glm::vec3(cells) * spacing();
  min += shift;
  max += shift;
  const glm::ivec3 d = glm::max(dims, glm::ivec3(1));
  scroll = ((scroll + cells) % d + d) % d;
}

namespace {

// The cell holding p (clamped to the grid) and p's place in it: what both
// cage() and its reference start from.
struct Cell {
  glm::vec3 spacing;
  glm::ivec3 base;  // the cell's lower corner, grid coordinates
  glm::vec3 f;      // p's fraction across the cell, per axis
};
Cell cell_of(const ProbeGrid& grid, const glm::vec3& p) {
  const glm::vec3 s = grid.spacing();
  glm::vec3 g(0.0f);
  for (int a = 0; a < 3; ++a)
    if (grid.dims[a] > 1 && s[a] > 0)
      g[a] = std::clamp((p[a] - grid.min[a]) / s[a], 0.0f, static_cast<float>(grid.dims[a] - 1));
  const glm::ivec3 base = glm::min(glm::ivec3(glm::floor(g)), glm::max(grid.dims - 2, glm::ivec3(0)));
  return {s, base, glm::clamp(g - glm::vec3(base), glm::vec3(0.0f), glm::vec3(1.0f))};
}

}  // namespace

ProbeGrid::Cage ProbeGrid::cage_reference(const glm::vec3& p) const {
  const auto [s, base, f] = cell_of(*this, p);
  Cage c;
  for (int i = 0; i < 8; ++i) {
    const glm::ivec3 o((i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1);
    const glm::ivec3 q = glm::min(base + o, dims - 1);
    const int at = index(q);
    c.probes[static_cast<std::size_t>(i)] = at;
    c.weights[static_cast<std::size_t>(i)] = (o.x ? f.x : 1 - f.x) * (o.y ? f.y : 1 - f.y) * (o.z ? f.z : 1 - f.z);
    c.positions[static_cast<std::size_t>(i)] =
        min + glm::vec3(q) * s + (offsets.empty() ? glm::vec3(0.0f) : offsets[static_cast<std::size_t>(at)]);
  }
  return c;
}

ProbeGrid::Cage ProbeGrid::cage(const glm::vec3& p) const {
  const auto [s, base, f] = cell_of(*this, p);
  // Per axis and side (0 = base, 1 = base + 1, clamped): the storage
  // coordinate, the world coordinate and the weight factor, in the
  // reference's arithmetic.
  int stored[3][2];
  float at[3][2], w[3][2];
  for (int a = 0; a < 3; ++a)
    for (int o = 0; o < 2; ++o) {
      const int q = std::min(base[a] + o, dims[a] - 1);
      int c = q + scroll[a];
      if (c >= dims[a]) c -= dims[a];
      stored[a][o] = c;
      at[a][o] = min[a] + static_cast<float>(q) * s[a];
      w[a][o] = o ? f[a] : 1 - f[a];
    }
  Cage c;
  for (int i = 0; i < 8; ++i) {
    const int ox = i & 1, oy = (i >> 1) & 1, oz = (i >> 2) & 1;
    c.probes[static_cast<std::size_t>(i)] = (stored[2][oz] * dims.y + stored[1][oy]) * dims.x + stored[0][ox];
    c.weights[static_cast<std::size_t>(i)] = w[0][ox] * w[1][oy] * w[2][oz];
    c.positions[static_cast<std::size_t>(i)] = glm::vec3(at[0][ox], at[1][oy], at[2][oz]);
  }
  if (!offsets.empty())
    for (std::size_t i = 0; i < 8; ++i) c.positions[i] += offsets[static_cast<std::size_t>(c.probes[i])];
  return c;
}

}  // namespace transgi::probes
