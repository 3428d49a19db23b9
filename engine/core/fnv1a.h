#pragma once
// FNV-1a, 64 bit: content hashes and cache keys (not cryptographic; it
// tells apart inputs that differ, which is all a cache or staleness check needs).
#include <cstdint>
#include <type_traits>
#include <vector>

namespace engine::core {

struct Fnv1a {
  std::uint64_t h = 1469598103934665603ull;

  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes(&v, sizeof(T));
  }
  // The length first, so ["ab"] and ["a", "b"]-like splits differ.
  template <class T>
  void vec(const std::vector<T>& v) {
    value(static_cast<std::uint64_t>(v.size()));
    bytes(v.data(), v.size() * sizeof(T));
  }
};

}  // namespace engine::core
