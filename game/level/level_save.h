#pragma once
// Saving the edited level: the glTF's own nodes (not what game.json added)
// with their current transforms, lights and cameras, the level's meshes and
// materials, its images and environment map as the source file named them.
// The mesh data is unchanged, so the level's baked GI model stays valid.
// Written atomically (a temporary file, then a rename).
#include <cstdint>
#include <filesystem>
#include <vector>

#include "engine/ecs/world.h"

namespace game {

// What the glTF loaded, recorded before the game adds anything.
struct LevelOrigin {
  std::filesystem::path source;
  std::size_t meshes = 0, materials = 0;
  std::vector<engine::ecs::Entity> entities;
};

// Writes `out` (default: the source file itself) and its .bin; returns the path.
std::filesystem::path save_level_gltf(engine::ecs::World& world, const std::filesystem::path& out = {});

}  // namespace game
