#pragma once
// Dense per-process ids for component and resource types, so storages can
// live in a vector indexed by type instead of a hash map.
#include <atomic>
#include <cstdint>
#include <string_view>

namespace engine::ecs {

using TypeId = std::uint32_t;

namespace detail {
inline std::atomic<TypeId> next_type_id{0};

template <class T>
constexpr std::string_view type_name() {
  std::string_view s = __PRETTY_FUNCTION__;
  const auto begin = s.find("T = ") + 4;
  const auto end = s.find_first_of(";]", begin);
  return s.substr(begin, end - begin);
}
}  // namespace detail

template <class T>
TypeId type_id() {
  static const TypeId id = detail::next_type_id.fetch_add(1, std::memory_order_relaxed);
  return id;
}

template <class T>
constexpr std::string_view type_name() {
  return detail::type_name<T>();
}

}  // namespace engine::ecs
