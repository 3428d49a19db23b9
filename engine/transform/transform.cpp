#include "engine/transform/transform.h"

#include <glm/gtc/matrix_transform.hpp>

namespace engine::transform {

glm::mat4 Similarity::matrix() const {
  glm::mat4 m = glm::mat4_cast(rotation) * scale;
  m[3] = glm::vec4(translation, 1.0f);
  return m;
}

Similarity Similarity::inverse() const {
  Similarity inv;
  inv.rotation = glm::conjugate(rotation);
  inv.scale = 1.0f / scale;
  inv.translation = -(inv.rotation * (inv.scale * translation));
  return inv;
}

Similarity Similarity::operator*(const Similarity& child) const {
  Similarity out;
  out.translation = apply_point(child.translation);
  out.rotation = glm::normalize(rotation * child.rotation);
  out.scale = scale * child.scale;
  return out;
}

}  // namespace engine::transform
