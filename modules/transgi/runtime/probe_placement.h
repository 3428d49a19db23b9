#pragma once
// Where a world's TransGI probes go, as the tools and the game choose it:
// camera-centred cascades (the default for content that is not a closed
// room), or one grid over the scene's bounds (the paper's setting).
#include <cstddef>
#include <memory>
#include <vector>
#include <string_view>

#include <glm/glm.hpp>

#include "engine/ecs/world.h"
#include "probes/cascades.h"
#include "probes/probe_field.h"

namespace transgi::runtime {

enum class ProbeVolumeMode {
  // ProbeCascades around the camera (probes/cascades.h): probe density
  // follows the viewer, whatever the scene's extent.
  Cascades,
  // One ProbeVolume fitted to the scene's bounds: right for a closed room,
  // wrong for a level on a ground plane or terrain (probes tens of metres
  // apart, nearly all outside).
  Scene,
  // Only the volumes authored in the scene: glTF nodes whose
  // extras.transgi_probe_volume is set (a box, the node's scale its half
  // extents). With Cascades they are used too, and take precedence inside.
  Authored,
};

struct ProbePlacement {
  ProbeVolumeMode mode = ProbeVolumeMode::Cascades;
  glm::ivec3 scene_dims{8};            // Scene: probes per axis
  probes::CascadeSettings cascades{};  // Cascades
};

[[nodiscard]] std::string_view name_of(ProbeVolumeMode mode);

// The glTF extras key that marks an authored probe volume.
inline constexpr std::string_view kProbeVolumeMarker = "transgi_probe_volume";

// A node marked kProbeVolumeMarker and its box: the axis-aligned bounds of
// its scaled, rotated unit cube, with about `cells_along_longest` cells on
// the longest axis and proportionally fewer on the others (2 to 16). Throws
// naming the node if its box is degenerate or not finite, or it has a parent.
struct AuthoredBox {
  engine::ecs::Entity node;
  glm::vec3 min{0.0f}, max{0.0f};
  glm::ivec3 dims{8};
};
std::vector<AuthoredBox> authored_boxes(engine::ecs::World& world, int cells_along_longest = 8);

// Gives every node marked kProbeVolumeMarker a ProbeVolume over its box (the
// axis-aligned bounds of the node's scaled, rotated unit cube), with about
// `cells_along_longest` cells on its longest axis and proportionally fewer on
// the others (2 to 16). Throws naming the node if its box is degenerate or
// not finite. Returns how many it gave one.
std::size_t attach_authored_volumes(engine::ecs::World& world, int cells_along_longest = 8);

// Every probe field of the world in the order shading consults them
// (ProbeVolumes, then each ProbeCascades' fields, finest first), for tools
// that show or report them.
std::vector<std::shared_ptr<const probes::ProbeField>> probe_fields(engine::ecs::World& world);

// Spawns what the placement asks for (authored volumes are attached to their
// nodes in Cascades and Authored mode). Throws if Authored finds none.
void spawn_probes(engine::ecs::World& world, const ProbePlacement& placement);

}  // namespace transgi::runtime
