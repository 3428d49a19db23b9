#pragma once
// Keeps the SceneLights resource (the LightSet renderers sample) in step with
// the world. Runs in PrepareRender after the Embree sync. What holds after
// it: SceneLights::set holds this frame's emissive triangles (in world
// space), enabled punctual lights and the environment; `version` increased
// exactly when one of those changed this frame, and `geometry_version`
// exactly when the Embree scene did, so per-frame caches (light probes) can
// tell that their inputs moved.
#include "engine/app/app.h"
#include "engine/render/light_set.h"

namespace engine::render {

struct SceneLights {
  LightSet set;
  std::uint64_t version = 0;           // lighting changed (lights, emitters, environment)
  std::uint64_t geometry_version = 0;  // the ray-traced geometry changed
};

class LightPlugin final : public app::Plugin {
 public:
  void build(app::App& app) override;
  [[nodiscard]] std::string_view name() const override { return "engine::LightPlugin"; }
};

}  // namespace engine::render
