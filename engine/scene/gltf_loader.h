#pragma once
// glTF 2.0 import (.gltf and .glb) into entities.
//
// The importer takes control of everything tinygltf would otherwise do on
// its own with untrusted input: file access (regular files inside the
// scene's folder, size-capped, no shell expansion), JSON nesting depth and
// the GLB container (checked before parsing), image decoding (PNG/JPEG by
// magic bytes, dimension caps) and every buffer access (range-checked before
// any byte is read). Failures throw GltfError naming the file and the field.
//
// Result: one entity per node of the default scene with Transform (+ Parent),
// Name, and MeshInstance / Camera / PunctualLight as the node has them; the
// SceneAssets resource holds meshes (one per glTF mesh, shared by every node
// that uses it), materials, textures and the environment light read from
// scenes[s].extras.environment (docs/scene-format.md).
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "engine/ecs/world.h"
#include "engine/transform/transform.h"

namespace engine::scene {

class GltfError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct GltfLoadOptions {
  std::uint64_t max_file_bytes = 1ull << 30;  // per file: the .gltf/.glb, each buffer, each image
  int max_json_depth = 64;
  int max_texture_dimension = 16384;
  bool load_environment = true;
};

// Where an entity came from, so an editor can write its edits back into the
// same node of the same file: the node index and the local transform as
// loaded (a node whose non-uniform scale was baked into its mesh has
// `baked_scale` set and cannot take a new transform without re-baking).
struct GltfNodeSource {
  std::uint32_t node = 0;
  transform::Transform loaded;
  bool baked_scale = false;
};

// The markers a node's extras set: each top-level key of nodes[i].extras whose
// value is true, a non-zero number, or a non-empty object (tinygltf drops
// empty objects and nulls) -- e.g. "transgi_probe_volume": true -- for
// modules to find their own (a probe volume, a spawn point). Only
// nodes with at least one get it. `scale` is the node's whole scale,
// non-uniform part included, which a Transform (a similarity) cannot hold:
// a marker that stands for a box (a Blender empty cube) reads it as its half
// extents.
struct NodeMarkers {
  std::vector<std::string> keys;
  glm::vec3 scale{1.0f};
  [[nodiscard]] bool has(std::string_view key) const {
    for (const std::string& k : keys)
      if (k == key) return true;
    return false;
  }
};

struct GltfLoadResult {
  std::vector<ecs::Entity> entities;  // in node order of the default scene (depth first)
  std::size_t mesh_count = 0;
  std::size_t triangle_count = 0;
  std::vector<std::string> warnings;
};

GltfLoadResult load_gltf(ecs::World& world, const std::filesystem::path& path, const GltfLoadOptions& options = {});

}  // namespace engine::scene
