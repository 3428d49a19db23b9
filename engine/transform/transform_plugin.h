#pragma once
// Propagates Transform + Parent into WorldTransform in PostUpdate.
#include "engine/app/app.h"
#include "engine/schedule/system_param.h"
#include "engine/transform/transform.h"

namespace engine::transform {

// Counters for the last propagation, for tests and profiling.
struct TransformStats {
  std::size_t visited = 0;    // entities whose world transform was recomputed
  std::size_t changed = 0;    // ... of which the value actually changed
  std::size_t inserted = 0;   // entities that got their first WorldTransform
  std::size_t unreachable = 0;  // in a parent cycle; left untouched
};

class TransformPlugin final : public app::Plugin {
 public:
  void build(app::App& app) override;
  [[nodiscard]] std::string_view name() const override { return "engine::TransformPlugin"; }
};

}  // namespace engine::transform
