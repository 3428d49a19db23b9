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

ProbeGrid::Cage ProbeGrid::cage(const glm::vec3& p) const {
  const glm::vec3 s = spacing();
  glm::vec3 g(0.0f);
  for (int a = 0; a < 3; ++a)
    if (dims[a] > 1 && s[a] > 0) g[a] = std::clamp((p[a] - min[a]) / s[a], 0.0f, static_cast<float>(dims[a] - 1));
  const glm::ivec3 base = glm::min(glm::ivec3(glm::floor(g)), glm::max(dims - 2, glm::ivec3(0)));
  const glm::vec3 f = glm::clamp(g - glm::vec3(base), glm::vec3(0.0f), glm::vec3(1.0f));
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

}  // namespace transgi::probes
