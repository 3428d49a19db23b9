#include "probes/probe_grid.h"

#include <algorithm>
#include <cmath>

namespace transgi::probes {

ProbeGrid::Cage ProbeGrid::cage(const glm::vec3& p) const {
  const glm::vec3 g = glm::clamp((p - min) / spacing(), glm::vec3(0.0f), glm::vec3(dims - 1));
  const glm::ivec3 base = glm::min(glm::ivec3(glm::floor(g)), glm::max(dims - 2, glm::ivec3(0)));
  const glm::vec3 f = glm::clamp(g - glm::vec3(base), glm::vec3(0.0f), glm::vec3(1.0f));
  Cage c;
  for (int i = 0; i < 8; ++i) {
    const glm::ivec3 o((i >> 0) & 1, (i >> 1) & 1, (i >> 2) & 1);
    const glm::ivec3 q = glm::min(base + o, dims - 1);
    c.probes[static_cast<std::size_t>(i)] = index(q);
    c.weights[static_cast<std::size_t>(i)] = (o.x ? f.x : 1 - f.x) * (o.y ? f.y : 1 - f.y) * (o.z ? f.z : 1 - f.z);
  }
  return c;
}

}  // namespace transgi::probes
