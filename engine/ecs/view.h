#pragma once
// A view iterates the entities that have every component in Get<...> and none
// in Exclude<...>. `const T` means read; plain `T` means write, and every
// entity the view hands out mutably is stamped as changed at this_run (any
// mutable access counts as a change, as in Bevy's Mut<T>).
#include <algorithm>
#include <array>
#include <utility>
#include <cstddef>
#include <tuple>
#include <type_traits>

#include "engine/ecs/storage.h"
#include "engine/ecs/view_fwd.h"
#include "engine/jobs/parallel_for.h"

namespace engine::ecs {

class World;

template <class... Ts, class... Xs>
class View<Get<Ts...>, Exclude<Xs...>> {
  static_assert(sizeof...(Ts) > 0, "a view needs at least one component in Get<...>");

  template <class T>
  using StoragePtr = std::conditional_t<std::is_const_v<T>, const Storage<std::remove_const_t<T>>*,
                                        Storage<std::remove_const_t<T>>*>;

 public:
  View(World& world, Tick last_run, Tick this_run);

  // Calls fn(Entity, Ts&...) or fn(Ts&...) for every matching entity.
  template <class Fn>
  void each(Fn&& fn) const {
    const StorageBase* driver = smallest();
    if (!driver) return;
    const auto& owners = driver->entities();
    for (std::size_t i = 0; i < owners.size(); ++i) visit(driver, static_cast<std::uint32_t>(i), owners[i], fn);
  }

  // Data-parallel each(): fn must only touch this entity's components. The
  // split into chunks does not depend on the thread count.
  template <class Fn>
  void par_each(Fn&& fn, std::size_t grain = 1024) const {
    const StorageBase* driver = smallest();
    if (!driver) return;
    const auto& owners = driver->entities();
    jobs::parallel_for(std::size_t{0}, owners.size(), grain,
                       [&](std::size_t begin, std::size_t end) {
                         for (std::size_t i = begin; i < end; ++i)
                           visit(driver, static_cast<std::uint32_t>(i), owners[i], fn);
                       });
  }

  [[nodiscard]] bool contains(Entity e) const {
    if (!all_present()) return false;
    return (std::get<StoragePtr<Ts>>(get_)->contains(e) && ...) && !excluded(e);
  }

  // Point access to one of the view's components. read() never counts as a
  // change; write() does, and needs T to be a write (non-const) component.
  template <class T>
  [[nodiscard]] const std::remove_const_t<T>* try_read(Entity e) const {
    const auto* s = storage_of<T>();
    return s ? s->find(e) : nullptr;
  }
  template <class T>
  [[nodiscard]] std::remove_const_t<T>* try_write(Entity e) const {
    using U = std::remove_const_t<T>;
    static_assert((std::is_same_v<U, Ts> || ...), "write() needs a non-const component in Get<...>");
    auto* s = std::get<StoragePtr<U>>(get_);
    if (!s) return nullptr;
    const std::uint32_t slot = s->slot_or_none(e);
    if (slot == Storage<U>::kNone) return nullptr;
    s->mark_changed_slot(slot, this_run_);
    return &s->at_slot(slot);
  }

  // Was T added to / changed on e after the owning system last ran?
  template <class T>
  [[nodiscard]] bool is_added(Entity e) const {
    return storage_of<T>()->added_tick(e) > last_run_;
  }
  template <class T>
  [[nodiscard]] bool is_changed(Entity e) const {
    return storage_of<T>()->changed_tick(e) > last_run_;
  }

  [[nodiscard]] std::size_t size_hint() const {
    const StorageBase* d = smallest();
    return d ? d->size() : 0;
  }
  [[nodiscard]] Tick last_run() const { return last_run_; }
  [[nodiscard]] Tick this_run() const { return this_run_; }

 private:
  template <class T>
  auto storage_of() const {
    using U = std::remove_const_t<T>;
    constexpr bool has_read = (std::is_same_v<const U, Ts> || ...);
    constexpr bool has_write = (std::is_same_v<U, Ts> || ...);
    static_assert(has_read || has_write, "component is not in this view's Get<...>");
    if constexpr (has_read) return std::get<StoragePtr<const U>>(get_);
    else return std::get<StoragePtr<U>>(get_);
  }

  [[nodiscard]] bool all_present() const { return ((std::get<StoragePtr<Ts>>(get_) != nullptr) && ...); }

  [[nodiscard]] const StorageBase* smallest() const {
    if (!all_present()) return nullptr;
    const StorageBase* best = nullptr;
    ((best = (!best || std::get<StoragePtr<Ts>>(get_)->size() < best->size())
                 ? static_cast<const StorageBase*>(std::get<StoragePtr<Ts>>(get_))
                 : best),
     ...);
    return best;
  }

  [[nodiscard]] bool excluded([[maybe_unused]] Entity e) const {
    return ((std::get<const Storage<Xs>*>(exclude_) && std::get<const Storage<Xs>*>(exclude_)->contains(e)) ||
            ... || false);
  }

  // Dense slot of e in T's storage, or kNone. The driver's slot is known.
  template <class T>
  std::uint32_t slot_in(const StorageBase* driver, std::uint32_t driver_slot, Entity e) const {
    auto* s = std::get<StoragePtr<T>>(get_);
    if (static_cast<const StorageBase*>(s) == driver) return driver_slot;
    return s->slot_or_none(e);
  }

  template <class T>
  T& fetch_slot(std::uint32_t slot) const {
    auto* s = std::get<StoragePtr<T>>(get_);
    if constexpr (!std::is_const_v<T>) s->mark_changed_slot(slot, this_run_);
    return s->at_slot(slot);
  }

  template <class Fn>
  void visit(const StorageBase* driver, std::uint32_t driver_slot, Entity e, Fn& fn) const {
    const std::array<std::uint32_t, sizeof...(Ts)> slots{slot_in<Ts>(driver, driver_slot, e)...};
    for (std::uint32_t s : slots)
      if (s == StorageBase::kNoSlotPublic) return;
    if (excluded(e)) return;
    call(fn, e, slots, std::index_sequence_for<Ts...>{});
  }

  template <class Fn, std::size_t... I>
  void call(Fn& fn, Entity e, const std::array<std::uint32_t, sizeof...(Ts)>& slots, std::index_sequence<I...>) const {
    if constexpr (std::is_invocable_v<Fn&, Entity, Ts&...>) {
      fn(e, fetch_slot<Ts>(slots[I])...);
    } else {
      static_assert(std::is_invocable_v<Fn&, Ts&...>, "each() callback must take (Entity, Ts&...) or (Ts&...)");
      fn(fetch_slot<Ts>(slots[I])...);
    }
  }

  std::tuple<StoragePtr<Ts>...> get_;
  std::tuple<const Storage<Xs>*...> exclude_;
  Tick last_run_;
  Tick this_run_;
};

}  // namespace engine::ecs

#include "engine/ecs/world.h"

namespace engine::ecs {
template <class... Ts, class... Xs>
View<Get<Ts...>, Exclude<Xs...>>::View(World& world, Tick last_run, Tick this_run)
    : get_(world.template find_storage<std::remove_const_t<Ts>>()...),
      exclude_(std::as_const(world).template find_storage<Xs>()...),
      last_run_(last_run),
      this_run_(this_run) {}
}  // namespace engine::ecs
