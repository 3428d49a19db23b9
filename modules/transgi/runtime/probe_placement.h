#pragma once
// Where a world's TransGI probes go, as the tools and the game choose it:
// camera-centred cascades (the default for content that is not a closed
// room), or one grid over the scene's bounds (the paper's setting).
#include <string_view>

#include <glm/glm.hpp>

#include "engine/ecs/world.h"
#include "probes/cascades.h"

namespace transgi::runtime {

enum class ProbeVolumeMode {
  // ProbeCascades around the camera (probes/cascades.h): probe density
  // follows the viewer, whatever the scene's extent.
  Cascades,
  // One ProbeVolume fitted to the scene's bounds: right for a closed room,
  // wrong for a level on a ground plane or terrain (probes tens of metres
  // apart, nearly all outside).
  Scene,
};

struct ProbePlacement {
  ProbeVolumeMode mode = ProbeVolumeMode::Cascades;
  glm::ivec3 scene_dims{8};            // Scene: probes per axis
  probes::CascadeSettings cascades{};  // Cascades
};

[[nodiscard]] std::string_view name_of(ProbeVolumeMode mode);

// Spawns the entity the placement asks for and returns it.
engine::ecs::Entity spawn_probes(engine::ecs::World& world, const ProbePlacement& placement);

}  // namespace transgi::runtime
