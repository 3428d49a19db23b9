#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/transform/transform_plugin.h"

namespace engine::rt {

namespace {

using namespace engine::schedule;
using scene::MeshInstance;
using transform::WorldTransform;
using InstanceView = View<Get<const MeshInstance, const WorldTransform>>;

void apply(const InstanceView& instances, const std::vector<Entity>& removed_meshes,
           const std::vector<Entity>& removed_worlds, const scene::SceneAssets& assets, RtScene& rt) {
  rt.set_assets(&assets);
  const bool rebuilt = rt.empty();  // new assets: every instance must be (re)added
  for (Entity e : removed_meshes) rt.remove_instance(e);
  for (Entity e : removed_worlds) rt.remove_instance(e);
  instances.each([&](Entity e, const MeshInstance& m, const WorldTransform& w) {
    if (rebuilt || instances.is_changed<MeshInstance>(e) || instances.is_changed<WorldTransform>(e))
      rt.upsert_instance(e, m.mesh, w);
  });
  rt.commit();
}

void sync(InstanceView instances, Removed<MeshInstance> removed_meshes, Removed<WorldTransform> removed_worlds,
          Res<scene::SceneAssets> assets, ResMut<RtScene> rt) {
  apply(instances, removed_meshes.entities, removed_worlds.entities, *assets, *rt);
}

}  // namespace

void sync_rt_scene(ecs::World& world, ecs::Tick since) {
  apply(InstanceView(world, since, world.change_tick()), world.removed_since<MeshInstance>(since),
        world.removed_since<WorldTransform>(since), world.resource<scene::SceneAssets>(), world.resource<RtScene>());
}

void RtPlugin::build(app::App& app) {
  app.add_plugin<transform::TransformPlugin>();
  if (!app.world().has_resource<RtScene>()) app.world().insert_resource<RtScene>();
  if (!app.world().has_resource<scene::SceneAssets>()) app.world().insert_resource<scene::SceneAssets>();
  app.add_system(Phase::PrepareRender, "rt::sync_scene", sync);
}

}  // namespace engine::rt
