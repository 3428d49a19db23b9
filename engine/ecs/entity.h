#pragma once
// An entity is an index into the world's slot table plus the generation the
// slot had when the handle was made. Despawning bumps the slot's generation,
// so an old handle to a reused slot no longer matches and is reported stale.
#include <cstdint>
#include <functional>

namespace engine::ecs {

struct Entity {
  static constexpr std::uint32_t kInvalidIndex = 0xffffffffu;

  std::uint32_t index = kInvalidIndex;
  std::uint32_t generation = 0;

  [[nodiscard]] constexpr bool is_null() const { return index == kInvalidIndex; }
  friend constexpr bool operator==(Entity, Entity) = default;
  friend constexpr auto operator<=>(Entity, Entity) = default;
};

inline constexpr Entity kNullEntity{};

// Monotonic change tick. 64 bits so that "changed since" comparisons never
// have to deal with wrap-around, even at millions of system runs per second.
using Tick = std::uint64_t;

}  // namespace engine::ecs

template <>
struct std::hash<engine::ecs::Entity> {
  std::size_t operator()(engine::ecs::Entity e) const noexcept {
    return std::hash<std::uint64_t>{}((std::uint64_t{e.generation} << 32) | e.index);
  }
};
