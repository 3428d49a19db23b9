#include "engine/ecs/world.h"

#include <limits>

namespace engine::ecs {

namespace {
// A slot whose generation would wrap is retired instead of reused, so a very
// old handle can never match a new entity.
constexpr std::uint32_t kRetiredGeneration = std::numeric_limits<std::uint32_t>::max();
}  // namespace

Entity World::spawn() {
  flush();  // keep reserved handles valid before handing out more slots
  if (!free_list_.empty()) {
    const std::uint32_t index = free_list_.back();
    free_list_.pop_back();
    is_alive_[index] = 1;
    ++live_count_;
    return {index, generations_[index]};
  }
  const auto index = static_cast<std::uint32_t>(generations_.size());
  if (index == Entity::kInvalidIndex) throw EcsError("entity index space exhausted");
  generations_.push_back(0);
  is_alive_.push_back(1);
  ++live_count_;
  return {index, 0};
}

bool World::despawn(Entity e) {
  if (!alive(e)) return false;
  const Tick tick = change_tick();
  for (auto& s : storages_)
    if (s) s->erase(e, tick);
  is_alive_[e.index] = 0;
  --live_count_;
  if (++generations_[e.index] != kRetiredGeneration) free_list_.push_back(e.index);
  return true;
}

bool World::alive(Entity e) const {
  return e.index < generations_.size() && is_alive_[e.index] && generations_[e.index] == e.generation;
}

Entity World::reserve_entity() {
  std::scoped_lock lock(reserve_mutex_);
  Entity e;
  if (!free_list_.empty()) {
    // Slots on the free list already carry their next generation.
    const std::uint32_t index = free_list_.back();
    free_list_.pop_back();
    e = {index, generations_[index]};
  } else {
    const std::size_t index = generations_.size() + reserved_new_;
    if (index >= Entity::kInvalidIndex) throw EcsError("entity index space exhausted");
    ++reserved_new_;
    e = {static_cast<std::uint32_t>(index), 0};
  }
  reserved_.push_back(e);
  return e;
}

void World::flush() {
  std::scoped_lock lock(reserve_mutex_);
  if (reserved_.empty()) return;
  generations_.resize(generations_.size() + reserved_new_, 0);
  is_alive_.resize(generations_.size(), 0);
  for (const Entity e : reserved_) {
    is_alive_[e.index] = 1;
    ++live_count_;
  }
  reserved_.clear();
  reserved_new_ = 0;
}

void World::trim_removals(Tick up_to) {
  for (auto& s : storages_)
    if (s) s->trim_removals(up_to);
}

void World::require_alive(Entity e, const char* what) const {
  if (!alive(e))
    throw EcsError(std::string(what) + ": stale or invalid entity handle (index " + std::to_string(e.index) +
                   ", generation " + std::to_string(e.generation) + ")");
}

std::string World::missing_message(Entity e, std::string_view type) {
  return "entity (index " + std::to_string(e.index) + ", generation " + std::to_string(e.generation) +
         ") has no component " + std::string(type) + " or is not alive";
}

}  // namespace engine::ecs
