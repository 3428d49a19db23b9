#pragma once
// Keeps the RtScene resource in step with the world in PrepareRender:
// Added/Changed MeshInstance or WorldTransform -> instance upsert (a moved
// entity is only a transform update); Removed MeshInstance -> detach; then
// one top-level commit if anything changed.
#include "engine/app/app.h"
#include "engine/rt/rt_scene.h"

namespace engine::rt {

class RtPlugin final : public app::Plugin {
 public:
  void build(app::App& app) override;
  [[nodiscard]] std::string_view name() const override { return "engine::RtPlugin"; }
};

// The sync step on its own, for callers without an App (tools, tests).
void sync_rt_scene(ecs::World& world, ecs::Tick since);

}  // namespace engine::rt
