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
  // Bumped by whoever edits these assets in place at run time (the sky's yaw
  // or strength, a material's knobs), so the light set, the sun split and
  // the probes that follow them rebuild. Not `generation`: a new generation
  // means a different scene, and mirrors drop everything.
  std::uint64_t edit_version = 0;
};

// Next value for SceneAssets::generation.
std::uint64_t next_scene_generation();

}  // namespace engine::scene
