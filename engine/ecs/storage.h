#pragma once
// Sparse-set component storage: a paged sparse array maps entity index to a
// dense slot; components, their owners and their change ticks live densely so
// that views iterate contiguous memory. Removal is swap-and-pop.
#include <array>
#include <cassert>
#include <memory>
#include <utility>
#include <vector>

#include "engine/ecs/entity.h"

namespace engine::ecs {

class StorageBase {
 public:
  virtual ~StorageBase() = default;

  [[nodiscard]] bool contains(Entity e) const {
    const std::uint32_t slot = dense_slot(e.index);
    return slot != kNoSlot && owners_[slot] == e;
  }
  [[nodiscard]] std::size_t size() const { return owners_.size(); }
  [[nodiscard]] const std::vector<Entity>& entities() const { return owners_; }

  // Removes e's component if present, logging the removal at `tick` so that
  // systems can ask what was removed since they last ran.
  virtual bool erase(Entity e, Tick tick) = 0;

  [[nodiscard]] Tick added_tick(Entity e) const { return added_[slot_of(e)]; }
  [[nodiscard]] Tick changed_tick(Entity e) const { return changed_[slot_of(e)]; }
  void mark_changed(Entity e, Tick tick) { changed_[slot_of(e)] = tick; }
  void mark_changed_slot(std::uint32_t slot, Tick tick) { changed_[slot] = tick; }
  [[nodiscard]] Tick added_tick_slot(std::uint32_t slot) const { return added_[slot]; }
  [[nodiscard]] Tick changed_tick_slot(std::uint32_t slot) const { return changed_[slot]; }

  [[nodiscard]] std::uint32_t slot_of(Entity e) const {
    const std::uint32_t slot = dense_slot(e.index);
    assert(slot != kNoSlot && owners_[slot] == e);
    return slot;
  }

  static constexpr std::uint32_t kNoSlotPublic = 0xffffffffu;

  struct Removal {
    Entity entity;
    Tick tick;
  };
  [[nodiscard]] const std::vector<Removal>& removal_log() const { return removed_; }
  // Forgets removals no system can still need (all ran at or after `tick`).
  void trim_removals(Tick tick) {
    std::erase_if(removed_, [tick](const Removal& r) { return r.tick <= tick; });
  }

 protected:
  static constexpr std::uint32_t kNoSlot = 0xffffffffu;
  static constexpr std::size_t kPageSize = 4096;
  using Page = std::array<std::uint32_t, kPageSize>;

  [[nodiscard]] std::uint32_t dense_slot(std::uint32_t index) const {
    const std::size_t page = index / kPageSize;
    if (page >= pages_.size() || !pages_[page]) return kNoSlot;
    return (*pages_[page])[index % kPageSize];
  }
  std::uint32_t& sparse_ref(std::uint32_t index) {
    const std::size_t page = index / kPageSize;
    if (page >= pages_.size()) pages_.resize(page + 1);
    if (!pages_[page]) {
      pages_[page] = std::make_unique<Page>();
      pages_[page]->fill(kNoSlot);
    }
    return (*pages_[page])[index % kPageSize];
  }

  // Appends bookkeeping for a new dense slot; the derived class appends data.
  std::uint32_t push_slot(Entity e, Tick tick) {
    const auto slot = static_cast<std::uint32_t>(owners_.size());
    sparse_ref(e.index) = slot;
    owners_.push_back(e);
    added_.push_back(tick);
    changed_.push_back(tick);
    return slot;
  }
  // Moves the last slot into `slot` and pops; returns false if nothing moved.
  void pop_slot(std::uint32_t slot, Entity e, Tick tick) {
    const std::uint32_t last = static_cast<std::uint32_t>(owners_.size() - 1);
    if (slot != last) {
      owners_[slot] = owners_[last];
      added_[slot] = added_[last];
      changed_[slot] = changed_[last];
      sparse_ref(owners_[slot].index) = slot;
    }
    owners_.pop_back();
    added_.pop_back();
    changed_.pop_back();
    sparse_ref(e.index) = kNoSlot;
    removed_.push_back({e, tick});
  }

  std::vector<std::unique_ptr<Page>> pages_;
  std::vector<Entity> owners_;
  std::vector<Tick> added_;
  std::vector<Tick> changed_;
  std::vector<Removal> removed_;
};

template <class T>
class Storage final : public StorageBase {
 public:
  template <class... Args>
  T& emplace(Entity e, Tick tick, Args&&... args) {
    const std::uint32_t existing = dense_slot(e.index);
    if (existing != kNoSlot && owners_[existing] == e) {
      // Re-inserting replaces the value and counts as a change, not an add.
      data_[existing] = T{std::forward<Args>(args)...};
      changed_[existing] = tick;
      return data_[existing];
    }
    data_.emplace_back(std::forward<Args>(args)...);
    push_slot(e, tick);
    return data_.back();
  }

  bool erase(Entity e, Tick tick) override {
    const std::uint32_t slot = dense_slot(e.index);
    if (slot == kNoSlot || owners_[slot] != e) return false;
    const std::size_t last = data_.size() - 1;
    if (slot != last) data_[slot] = std::move(data_[last]);
    data_.pop_back();
    pop_slot(slot, e, tick);
    return true;
  }

  [[nodiscard]] T* find(Entity e) {
    const std::uint32_t slot = dense_slot(e.index);
    return (slot != kNoSlot && owners_[slot] == e) ? &data_[slot] : nullptr;
  }
  [[nodiscard]] const T* find(Entity e) const {
    const std::uint32_t slot = dense_slot(e.index);
    return (slot != kNoSlot && owners_[slot] == e) ? &data_[slot] : nullptr;
  }
  [[nodiscard]] T& at_slot(std::uint32_t slot) { return data_[slot]; }
  [[nodiscard]] const T& at_slot(std::uint32_t slot) const { return data_[slot]; }
  [[nodiscard]] std::uint32_t slot_or_none(Entity e) const {
    const std::uint32_t slot = dense_slot(e.index);
    return (slot != kNoSlot && owners_[slot] == e) ? slot : kNoSlot;
  }
  static constexpr std::uint32_t kNone = kNoSlot;

 private:
  std::vector<T> data_;
};

}  // namespace engine::ecs
