#include "runtime/probe_placement.h"

#include "runtime/components.h"

namespace transgi::runtime {

std::string_view name_of(ProbeVolumeMode mode) { return mode == ProbeVolumeMode::Cascades ? "cascades" : "scene"; }

engine::ecs::Entity spawn_probes(engine::ecs::World& world, const ProbePlacement& p) {
  const engine::ecs::Entity e = world.spawn();
  if (p.mode == ProbeVolumeMode::Cascades)
    world.emplace<ProbeCascades>(e, ProbeCascades{.cascades = p.cascades});
  else
    world.emplace<ProbeVolume>(e, ProbeVolume{.dims = p.scene_dims});
  return e;
}

}  // namespace transgi::runtime
