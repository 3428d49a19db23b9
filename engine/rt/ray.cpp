#include "engine/rt/ray.h"

#include <bit>
#include <cmath>

namespace engine::rt {

glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n, float scale) {
  const float kOrigin = scale / 32.0f;
  const float kFloatScale = scale / 65536.0f;
  constexpr float kIntScale = 256.0f;
  glm::vec3 out;
  for (int i = 0; i < 3; ++i) {
    const int of_i = static_cast<int>(kIntScale * n[i]);
    const int bits = std::bit_cast<int>(p[i]) + (p[i] < 0 ? -of_i : of_i);
    const float p_i = std::bit_cast<float>(bits);
    out[i] = std::abs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : p_i;
  }
  return out;
}

}  // namespace engine::rt
