#pragma once
// What a system reads and writes. Two systems conflict when one writes what
// the other reads or writes (components and resources separately), or when
// either needs the whole world. Conflicting systems never run at once.
#include <algorithm>
#include <string>
#include <vector>

#include "engine/ecs/type_id.h"

namespace engine::schedule {

struct Access {
  std::vector<ecs::TypeId> component_reads;
  std::vector<ecs::TypeId> component_writes;
  std::vector<ecs::TypeId> resource_reads;
  std::vector<ecs::TypeId> resource_writes;
  bool exclusive = false;  // takes World&: conflicts with everything
  bool reads_all = false;  // takes const World&: conflicts with every writer

  [[nodiscard]] bool writes_anything() const {
    return exclusive || !component_writes.empty() || !resource_writes.empty();
  }

  [[nodiscard]] bool conflicts_with(const Access& o) const {
    if (exclusive || o.exclusive) return true;
    if ((reads_all && o.writes_anything()) || (o.reads_all && writes_anything())) return true;
    return overlaps(component_writes, o.component_writes) || overlaps(component_writes, o.component_reads) ||
           overlaps(component_reads, o.component_writes) || overlaps(resource_writes, o.resource_writes) ||
           overlaps(resource_writes, o.resource_reads) || overlaps(resource_reads, o.resource_writes);
  }

 private:
  static bool overlaps(const std::vector<ecs::TypeId>& a, const std::vector<ecs::TypeId>& b) {
    return std::any_of(a.begin(), a.end(), [&](ecs::TypeId x) { return std::find(b.begin(), b.end(), x) != b.end(); });
  }
};

}  // namespace engine::schedule
