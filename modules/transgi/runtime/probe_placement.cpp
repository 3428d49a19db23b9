#include "runtime/probe_placement.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/scene/components.h"
#include "engine/scene/gltf_loader.h"
#include "engine/transform/transform.h"
#include "runtime/components.h"

namespace transgi::runtime {

std::string_view name_of(ProbeVolumeMode mode) {
  switch (mode) {
    case ProbeVolumeMode::Cascades: return "cascades";
    case ProbeVolumeMode::Scene: return "scene";
    case ProbeVolumeMode::Authored: return "authored";
  }
  return "?";
}

std::vector<AuthoredBox> authored_boxes(engine::ecs::World& world, int cells_along_longest) {
  using engine::scene::NodeMarkers;
  std::vector<AuthoredBox> found;
  world.view<const NodeMarkers, const engine::transform::Transform>().each(
      [&](engine::ecs::Entity e, const NodeMarkers& m, const engine::transform::Transform& t) {
        if (!m.has(kProbeVolumeMarker)) return;
        const engine::scene::Name* name = world.try_get<engine::scene::Name>(e);
        const std::string who = "node '" + (name ? name->value : std::string("?")) + "' (extras." + std::string(kProbeVolumeMarker) + ")";
        if (world.try_get<engine::transform::Parent>(e))
          throw std::runtime_error(who + ": a probe volume must be a root node (its box is read from its own transform)");
        // The rotated box's axis-aligned bounds: half extent on axis a is
        // sum_b |R[a][b]| x scale[b].
        const glm::mat3 r = glm::mat3_cast(t.rotation);
        glm::vec3 half(0.0f);
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) half[a] += std::abs(r[b][a]) * std::abs(m.scale[b]);
        if (!std::isfinite(half.x) || !std::isfinite(half.y) || !std::isfinite(half.z) || !std::isfinite(t.translation.x) ||
            !std::isfinite(t.translation.y) || !std::isfinite(t.translation.z))
          throw std::runtime_error(who + ": its translation or scale is not finite");
        if (!(std::min({half.x, half.y, half.z}) > 1e-4f))
          throw std::runtime_error(who + ": its box is flat (scale " + std::to_string(m.scale.x) + ", " + std::to_string(m.scale.y) +
                                   ", " + std::to_string(m.scale.z) + "): give every axis a size");
        const float cell = 2.0f * std::max({half.x, half.y, half.z}) / static_cast<float>(std::max(1, cells_along_longest));
        AuthoredBox box{e, t.translation - half, t.translation + half, glm::ivec3(2)};
        for (int a = 0; a < 3; ++a) box.dims[a] = std::clamp(static_cast<int>(std::lround(2.0f * half[a] / cell)), 2, 16);
        found.push_back(box);
      });
  return found;
}

std::size_t attach_authored_volumes(engine::ecs::World& world, int cells_along_longest) {
  const std::vector<AuthoredBox> boxes = authored_boxes(world, cells_along_longest);
  for (const AuthoredBox& b : boxes) world.emplace<ProbeVolume>(b.node, ProbeVolume{.min = b.min, .max = b.max, .dims = b.dims});
  return boxes.size();
}

std::vector<std::shared_ptr<const probes::ProbeField>> probe_fields(engine::ecs::World& world) {
  std::vector<std::shared_ptr<const probes::ProbeField>> out;
  world.view<const ProbeVolume>().each([&](const ProbeVolume& v) {
    if (v.field) out.push_back(v.field);
  });
  world.view<const ProbeCascades>().each([&](const ProbeCascades& c) {
    for (const auto& f : c.state.fields)
      if (f) out.push_back(f);
  });
  return out;
}

void spawn_probes(engine::ecs::World& world, const ProbePlacement& p) {
  switch (p.mode) {
    case ProbeVolumeMode::Scene:
      world.emplace<ProbeVolume>(world.spawn(), ProbeVolume{.dims = p.scene_dims});
      return;
    case ProbeVolumeMode::Cascades:
      attach_authored_volumes(world);
      world.emplace<ProbeCascades>(world.spawn(), ProbeCascades{.cascades = p.cascades});
      return;
    case ProbeVolumeMode::Authored:
      if (attach_authored_volumes(world) == 0)
        throw std::runtime_error("--probe-volume authored: the scene has no node whose extras." + std::string(kProbeVolumeMarker) +
                                 " is set (an empty node whose scale is the volume's half extents)");
      return;
  }
}

}  // namespace transgi::runtime
