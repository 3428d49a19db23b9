#pragma once
// World resource holding everything the importer shares between entities.
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "engine/material/material.h"
#include "engine/scene/environment.h"
#include "engine/scene/mesh_asset.h"
#include "engine/scene/texture.h"

namespace engine::scene {

struct SceneAssets {
  std::filesystem::path source;
  std::vector<std::shared_ptr<const MeshAsset>> meshes;
  std::vector<material::Material> materials;
  std::vector<Texture> textures;
  std::optional<Environment> environment;
};

}  // namespace engine::scene
