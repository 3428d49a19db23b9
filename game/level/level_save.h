#pragma once
// Saving the edited level: the source glTF's JSON with each of its own
// nodes' edits written back in place (transform; a light's colour,
// intensity and range), everything else kept as the file had it: meshes,
// materials, buffers, images, the environment. The mesh data is the same
// bytes, so the level's baked GI model stays valid; what game.json added is
// not part of the glTF and is not written. Written atomically (a temporary
// file, then a rename); saved into another folder, it takes the files it
// names (buffers, images, the sky) along, as a level loads only from its own.
#include <cstdint>
#include <filesystem>

#include "engine/ecs/world.h"

namespace game {

// The level's source file, recorded before the game adds anything.
struct LevelOrigin {
  std::filesystem::path source;
};

// Writes `out` (default: the source file itself); returns the path. Throws
// naming the node when an edit cannot be written (a moved node whose
// non-uniform scale was baked into its mesh).
std::filesystem::path save_level_gltf(engine::ecs::World& world, const std::filesystem::path& out = {});

}  // namespace game
