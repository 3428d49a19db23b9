#include "ddgi/octahedral.h"

#include <cmath>

namespace transgi::ddgi {

namespace {
glm::vec2 sign_not_zero(glm::vec2 v) { return {v.x >= 0 ? 1.0f : -1.0f, v.y >= 0 ? 1.0f : -1.0f}; }
}  // namespace

glm::vec2 octahedral_coordinates(const glm::vec3& d) {
  const float l1 = std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
  glm::vec2 uv = glm::vec2(d.x, d.y) / l1;
  if (d.z < 0) uv = (glm::vec2(1.0f) - glm::abs(glm::vec2(uv.y, uv.x))) * sign_not_zero(uv);
  return uv;
}

glm::vec3 octahedral_direction(glm::vec2 c) {
  glm::vec3 d(c.x, c.y, 1.0f - std::abs(c.x) - std::abs(c.y));
  if (d.z < 0) {
    const glm::vec2 xy = (glm::vec2(1.0f) - glm::abs(glm::vec2(d.y, d.x))) * sign_not_zero(glm::vec2(d.x, d.y));
    d.x = xy.x;
    d.y = xy.y;
  }
  return glm::normalize(d);
}

glm::vec3 texel_direction(int x, int y, int interior) {
  const glm::vec2 c = (glm::vec2(static_cast<float>(x), static_cast<float>(y)) + 0.5f) / static_cast<float>(interior) * 2.0f - 1.0f;
  return octahedral_direction(c);
}

}  // namespace transgi::ddgi
