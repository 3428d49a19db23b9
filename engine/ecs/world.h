#pragma once
// The world owns entities, component storages and resources.
//
// Threading contract (the scheduler relies on it):
//  - Reading and mutating *existing* components through storages that already
//    exist is safe from parallel systems whose access sets do not conflict.
//  - Structural changes (spawn, despawn, add/remove a component, creating a
//    storage or resource) happen only in exclusive contexts: outside the
//    schedule, inside a system that takes `World&`, or when deferred Commands
//    are applied at a phase's sync point.
//  - reserve_entity() is the one structural call that is safe from any thread:
//    it hands out a handle that becomes alive at the next flush().
#include <atomic>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/ecs/entity.h"
#include "engine/ecs/storage.h"
#include "engine/ecs/type_id.h"
#include "engine/ecs/view_fwd.h"

namespace engine::ecs {

// Thrown when a handle no longer refers to a live entity, or a component or
// resource that a caller requires is absent.
class EcsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class World {
 public:
  World() = default;
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // ---- entities -----------------------------------------------------------
  Entity spawn();
  // Despawns e and drops all its components. Returns false for stale handles.
  bool despawn(Entity e);
  [[nodiscard]] bool alive(Entity e) const;
  [[nodiscard]] std::size_t entity_count() const { return live_count_; }

  // Thread-safe: a handle that becomes alive at the next flush().
  Entity reserve_entity();
  // Makes reserved entities alive. Exclusive context only.
  void flush();

  // ---- components ---------------------------------------------------------
  template <class T, class... Args>
  T& emplace(Entity e, Args&&... args) {
    require_alive(e, "emplace");
    return storage<T>().emplace(e, change_tick(), std::forward<Args>(args)...);
  }
  template <class T>
  bool remove(Entity e) {
    if (!alive(e)) return false;
    auto* s = find_storage<T>();
    return s && s->erase(e, change_tick());
  }
  template <class T>
  [[nodiscard]] bool has(Entity e) const {
    const auto* s = find_storage<T>();
    return s && alive(e) && s->contains(e);
  }
  // Read access: never marks anything changed.
  template <class T>
  [[nodiscard]] const T* try_get(Entity e) const {
    const auto* s = find_storage<T>();
    return (s && alive(e)) ? s->find(e) : nullptr;
  }
  template <class T>
  [[nodiscard]] const T& get(Entity e) const {
    if (const T* p = try_get<T>(e)) return *p;
    throw EcsError(missing_message(e, type_name<T>()));
  }
  // Mutable access counts as a change (stamped with the current tick).
  template <class T>
  [[nodiscard]] T* try_get_mut(Entity e) {
    auto* s = find_storage<T>();
    if (!s || !alive(e)) return nullptr;
    T* p = s->find(e);
    if (p) s->mark_changed(e, change_tick());
    return p;
  }
  template <class T>
  [[nodiscard]] T& get_mut(Entity e) {
    if (T* p = try_get_mut<T>(e)) return *p;
    throw EcsError(missing_message(e, type_name<T>()));
  }
  // Explicit modification: runs fn on the component and marks it changed.
  template <class T, class Fn>
  void patch(Entity e, Fn&& fn) {
    std::forward<Fn>(fn)(get_mut<T>(e));
  }

  template <class T>
  Storage<T>& storage() {
    const TypeId id = type_id<T>();
    if (id >= storages_.size()) storages_.resize(id + 1);
    if (!storages_[id]) storages_[id] = std::make_unique<Storage<T>>();
    return static_cast<Storage<T>&>(*storages_[id]);
  }
  template <class T>
  [[nodiscard]] Storage<T>* find_storage() {
    const TypeId id = type_id<T>();
    return id < storages_.size() ? static_cast<Storage<T>*>(storages_[id].get()) : nullptr;
  }
  template <class T>
  [[nodiscard]] const Storage<T>* find_storage() const {
    const TypeId id = type_id<T>();
    return id < storages_.size() ? static_cast<const Storage<T>*>(storages_[id].get()) : nullptr;
  }

  // Entities whose T was removed (or whose owner was despawned) after `since`.
  template <class T>
  [[nodiscard]] std::vector<Entity> removed_since(Tick since) const {
    std::vector<Entity> out;
    if (const auto* s = find_storage<T>()) {
      for (const auto& r : s->removal_log())
        if (r.tick > since) out.push_back(r.entity);
    }
    return out;
  }
  void trim_removals(Tick up_to);

  // A view stamped with the current tick that reports every component as
  // added/changed (last_run = 0). Systems get views with their own ticks.
  template <class... Ts, class... Xs>
  View<Get<Ts...>, Exclude<Xs...>> view(Exclude<Xs...> = {});

  // ---- resources ----------------------------------------------------------
  template <class T, class... Args>
  T& insert_resource(Args&&... args) {
    const TypeId id = type_id<T>();
    if (id >= resources_.size()) resources_.resize(id + 1);
    resources_[id] = std::make_unique<ResourceBox<T>>(std::forward<Args>(args)...);
    return static_cast<ResourceBox<T>&>(*resources_[id]).value;
  }
  template <class T>
  [[nodiscard]] T* try_resource() {
    const TypeId id = type_id<T>();
    if (id >= resources_.size() || !resources_[id]) return nullptr;
    return &static_cast<ResourceBox<T>&>(*resources_[id]).value;
  }
  template <class T>
  [[nodiscard]] const T* try_resource() const {
    return const_cast<World*>(this)->try_resource<T>();
  }
  template <class T>
  [[nodiscard]] T& resource() {
    if (T* p = try_resource<T>()) return *p;
    throw EcsError("missing resource " + std::string(type_name<T>()));
  }
  template <class T>
  [[nodiscard]] const T& resource() const {
    return const_cast<World*>(this)->resource<T>();
  }
  template <class T>
  [[nodiscard]] bool has_resource() const {
    return try_resource<T>() != nullptr;
  }
  template <class T>
  bool remove_resource() {
    const TypeId id = type_id<T>();
    if (id >= resources_.size() || !resources_[id]) return false;
    resources_[id].reset();
    return true;
  }

  // ---- change ticks -------------------------------------------------------
  // The tick that direct (non-system) mutations are stamped with.
  [[nodiscard]] Tick change_tick() const { return change_tick_.load(std::memory_order_acquire); }
  // Claims a fresh tick for one system run and advances the world's tick, so
  // that every later mutation (direct, by a later system, or by Commands) is
  // stamped strictly after it and the system sees it on its next run.
  Tick claim_tick() { return change_tick_.fetch_add(1, std::memory_order_acq_rel); }

 private:
  struct ResourceBase {
    virtual ~ResourceBase() = default;
  };
  template <class T>
  struct ResourceBox final : ResourceBase {
    template <class... Args>
    explicit ResourceBox(Args&&... args) : value(std::forward<Args>(args)...) {}
    T value;
  };

  void require_alive(Entity e, const char* what) const;
  static std::string missing_message(Entity e, std::string_view type);

  std::vector<std::uint32_t> generations_;
  std::vector<std::uint8_t> is_alive_;
  std::vector<std::uint32_t> free_list_;
  std::size_t live_count_ = 0;

  std::mutex reserve_mutex_;
  std::vector<Entity> reserved_;
  std::uint32_t reserved_new_ = 0;  // fresh indices handed out past generations_.size()

  std::vector<std::unique_ptr<StorageBase>> storages_;
  std::vector<std::unique_ptr<ResourceBase>> resources_;
  std::atomic<Tick> change_tick_{1};
};

}  // namespace engine::ecs

#include "engine/ecs/view.h"

template <class... Ts, class... Xs>
engine::ecs::View<engine::ecs::Get<Ts...>, engine::ecs::Exclude<Xs...>> engine::ecs::World::view(
    Exclude<Xs...>) {
  return View<Get<Ts...>, Exclude<Xs...>>(*this, /*last_run=*/0, change_tick());
}
