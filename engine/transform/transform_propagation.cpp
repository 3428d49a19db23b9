#include <algorithm>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "engine/transform/transform_plugin.h"

namespace engine::transform {

namespace {

using namespace engine::schedule;

// Children lists rebuilt only when the hierarchy's shape changes.
struct Hierarchy {
  std::unordered_map<std::uint32_t, std::vector<Entity>> children;  // by parent index
  std::vector<Entity> roots;
  // The parent each entity is actually attached to (null for roots), and the
  // entities whose effective parent differs from the previous build: those
  // need a recompute even if their own components did not change (Parent
  // removed, parent despawned).
  std::unordered_map<std::uint32_t, Entity> effective_parent;
  std::unordered_set<std::uint32_t> reparented;
  bool valid = false;
};

using TransformView = View<Get<const Transform>>;
using ParentView = View<Get<const Parent>>;
using WorldView = View<Get<WorldTransform>>;

bool hierarchy_changed(const TransformView& transforms, const ParentView& parents, const Removed<Parent>& removed_parents,
                       const Removed<Transform>& removed_transforms) {
  if (!removed_parents.empty() || !removed_transforms.empty()) return true;
  bool changed = false;
  parents.each([&](Entity e, const Parent&) { changed = changed || parents.is_changed<Parent>(e); });
  if (changed) return true;
  transforms.each([&](Entity e, const Transform&) { changed = changed || transforms.is_added<Transform>(e); });
  return changed;
}

void rebuild(Hierarchy& h, const TransformView& transforms, const ParentView& parents) {
  h.children.clear();
  h.roots.clear();
  h.reparented.clear();
  std::unordered_map<std::uint32_t, Entity> effective;
  transforms.each([&](Entity e, const Transform&) {
    const Parent* p = parents.try_read<Parent>(e);
    // A parent that is gone or has no Transform makes the child a root.
    Entity parent = ecs::kNullEntity;
    if (p && p->entity != e && transforms.contains(p->entity)) {
      parent = p->entity;
      h.children[parent.index].push_back(e);
    } else {
      h.roots.push_back(e);
    }
    effective[e.index] = parent;
    const auto old = h.effective_parent.find(e.index);
    if (old == h.effective_parent.end() || old->second != parent) h.reparented.insert(e.index);
  });
  h.effective_parent = std::move(effective);
  h.valid = true;
}

void propagate_transforms(TransformView transforms, ParentView parents, WorldView worlds,
                          Removed<Parent> removed_parents, Removed<Transform> removed_transforms,
                          Local<Hierarchy> hierarchy, ResMut<TransformStats> stats, Commands& commands) {
  if (!hierarchy->valid || hierarchy_changed(transforms, parents, removed_parents, removed_transforms))
    rebuild(*hierarchy, transforms, parents);
  else
    hierarchy->reparented.clear();

  TransformStats s;
  struct Item {
    Entity entity;
    Similarity parent_world;
    bool parent_changed;
  };
  std::vector<Item> stack;
  for (Entity root : hierarchy->roots) stack.push_back({root, Similarity{}, false});

  std::size_t reached = 0;
  while (!stack.empty()) {
    const Item item = stack.back();
    stack.pop_back();
    ++reached;
    const Entity e = item.entity;
    const WorldTransform* current = worlds.try_read<WorldTransform>(e);
    const bool dirty = item.parent_changed || !current || transforms.is_changed<Transform>(e) ||
                       hierarchy->reparented.contains(e.index) ||
                       (parents.try_read<Parent>(e) && parents.is_changed<Parent>(e));

    Similarity world = current ? static_cast<const Similarity&>(*current) : Similarity{};
    bool world_changed = false;
    if (dirty) {
      ++s.visited;
      world = item.parent_world * *transforms.try_read<Transform>(e);
      if (!current) {
        commands.insert(e, WorldTransform{world});
        ++s.inserted;
        world_changed = true;
      } else if (!(world == static_cast<const Similarity&>(*current))) {
        static_cast<Similarity&>(*worlds.try_write<WorldTransform>(e)) = world;
        ++s.changed;
        world_changed = true;
      }
    }
    auto it = hierarchy->children.find(e.index);
    if (it == hierarchy->children.end()) continue;
    for (Entity child : it->second) stack.push_back({child, world, world_changed});
  }
  s.unreachable = transforms.size_hint() - std::min(transforms.size_hint(), reached);
  *stats = s;
}

}  // namespace

void TransformPlugin::build(app::App& app) {
  app.world().insert_resource<TransformStats>();
  app.add_system(Phase::PostUpdate, "transform::propagate", propagate_transforms);
}

}  // namespace engine::transform
