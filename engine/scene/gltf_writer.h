#pragma once
// Writes a scene as glTF 2.0 (.gltf + .bin), deterministically: the same
// description always gives the same bytes. Used by the content generator
// and by tools that save scenes. Files are written atomically.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "engine/material/material.h"
#include "engine/scene/components.h"
#include "engine/scene/mesh_asset.h"
#include "engine/transform/transform.h"

namespace engine::scene {

struct GltfNodeDesc {
  std::string name;
  int mesh = -1;
  transform::Transform transform;
  std::optional<Camera> camera;
  std::optional<PunctualLight> light;
  std::vector<int> children;
};

struct GltfEnvironmentDesc {
  std::string uri;  // relative to the .gltf
  float strength = 1.0f;
  glm::mat4 matrix{1.0f};
};

struct GltfSceneDesc {
  // Image URIs (PNG/JPEG next to the .gltf); texture i samples image i with
  // repeat wrapping. Materials refer to textures by index.
  std::vector<std::string> images;
  std::vector<MeshAsset> meshes;
  std::vector<material::Material> materials;
  std::vector<GltfNodeDesc> nodes;
  std::vector<int> roots;
  std::optional<GltfEnvironmentDesc> environment;
};

// Writes `path` and `<stem>.bin` beside it. Throws io::IoError.
void write_gltf(const std::filesystem::path& path, const GltfSceneDesc& scene);

}  // namespace engine::scene
