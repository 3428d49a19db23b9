#include "engine/scene/mesh_asset.h"

#include <atomic>
#include <limits>

#include "engine/scene/scene_assets.h"

namespace engine::scene {

std::uint64_t next_scene_generation() {
  static std::atomic<std::uint64_t> next{1};
  return next.fetch_add(1);
}

void MeshAsset::compute_bounds() {
  if (positions.empty()) {
    bounds_min = bounds_max = glm::vec3(0.0f);
    return;
  }
  bounds_min = glm::vec3(std::numeric_limits<float>::max());
  bounds_max = glm::vec3(std::numeric_limits<float>::lowest());
  for (const glm::vec3& p : positions) {
    bounds_min = glm::min(bounds_min, p);
    bounds_max = glm::max(bounds_max, p);
  }
}

void MeshAsset::generate_normals() {
  normals.assign(positions.size(), glm::vec3(0.0f));
  for (const glm::uvec3& t : triangles) {
    // The unnormalised cross product weights each face by its area.
    const glm::vec3 n = glm::cross(positions[t.y] - positions[t.x], positions[t.z] - positions[t.x]);
    normals[t.x] += n;
    normals[t.y] += n;
    normals[t.z] += n;
  }
  for (glm::vec3& n : normals) {
    const float len = glm::length(n);
    n = len > 0 ? n / len : glm::vec3(0, 0, 1);
  }
}

}  // namespace engine::scene
