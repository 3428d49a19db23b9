#pragma once
// Triangle mesh data shared by every entity that instances it. Positions and
// normals are in the mesh's object space.
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace engine::scene {

struct MeshAsset {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;      // one per vertex, unit length
  std::vector<glm::vec2> uvs;          // TEXCOORD_0, or empty
  std::vector<glm::uvec3> triangles;   // indices into the vertex arrays
  std::vector<std::uint32_t> triangle_material;  // index into SceneAssets::materials
  glm::vec3 bounds_min{0.0f};
  glm::vec3 bounds_max{0.0f};

  [[nodiscard]] std::size_t vertex_count() const { return positions.size(); }
  [[nodiscard]] std::size_t triangle_count() const { return triangles.size(); }
  void compute_bounds();
  // Area-weighted vertex normals from the triangles (for meshes without them).
  void generate_normals();
};

}  // namespace engine::scene
