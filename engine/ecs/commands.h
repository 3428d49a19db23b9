#pragma once
// Deferred structural changes. Systems record spawns, despawns and component
// inserts/removals while iterating; the scheduler applies each system's buffer
// at the phase's sync point, in system registration order, so the result does
// not depend on which system finished first.
#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

#include "engine/ecs/world.h"

namespace engine::ecs {

class Commands {
 public:
  Commands() = default;
  explicit Commands(World& world) : world_(&world) {}

  // A handle that is valid immediately and alive after the next apply().
  Entity spawn() { return world_->reserve_entity(); }

  template <class T>
  Commands& insert(Entity e, T value) {
    ops_.emplace_back([e, v = std::move(value)](World& w) mutable {
      if (!w.alive(e)) return false;
      w.emplace<T>(e, std::move(v));
      return true;
    });
    return *this;
  }
  template <class T>
  Commands& remove(Entity e) {
    ops_.emplace_back([e](World& w) {
      if (!w.alive(e)) return false;
      w.remove<T>(e);
      return true;
    });
    return *this;
  }
  Commands& despawn(Entity e) {
    ops_.emplace_back([e](World& w) { return w.despawn(e); });
    return *this;
  }
  // Arbitrary deferred work with exclusive world access.
  Commands& run(std::function<void(World&)> fn) {
    ops_.emplace_back([f = std::move(fn)](World& w) {
      f(w);
      return true;
    });
    return *this;
  }

  // Applies and clears the buffer. Ops that target an entity that is no
  // longer alive (despawned earlier in the same flush) are dropped; the count
  // is returned so callers can report it.
  std::size_t apply(World& world) {
    world.flush();
    std::size_t dropped = 0;
    for (auto& op : ops_)
      if (!op(world)) ++dropped;
    ops_.clear();
    return dropped;
  }
  [[nodiscard]] bool empty() const { return ops_.empty(); }
  [[nodiscard]] std::size_t size() const { return ops_.size(); }

 private:
  World* world_ = nullptr;
  std::vector<std::function<bool(World&)>> ops_;
};

}  // namespace engine::ecs
