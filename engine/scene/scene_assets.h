#pragma once
// World resource holding everything the importer shares between entities.
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>
#include <cstdint>



#include "engine/material/material.h"
#include "engine/scene/environment.h"
#include "engine/scene/mesh_asset.h"
#include "engine/scene/texture.h"

namespace engine::scene {

struct SceneAssets {
  // Unique per loaded scene, so mirrors (ray tracing, GPU) notice a reload.
  std::uint64_t generation = 0;
  std::filesystem::path source;
  std::vector<std::shared_ptr<const MeshAsset>> meshes;
  std::vector<material::Material> materials;
  std::vector<Texture> textures;
  std::optional<Environment> environment;
  // Bumped whenever the environment's yaw or strength changes at run time,
  // so the light set (and the caches that follow it) rebuild.
  std::uint64_t environment_version = 0;
  // Bumped whenever a material changes at run time (an editor's knob), for
  // the same reason: emission and reflectance feed the light set and probes.
  std::uint64_t material_version = 0;
};

// Next value for SceneAssets::generation.
std::uint64_t next_scene_generation();

}  // namespace engine::scene
