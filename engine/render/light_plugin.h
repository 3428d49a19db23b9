#pragma once
// Keeps the SceneLights resource (the LightSet renderers sample) in step with
// the world. Runs in PrepareRender after the Embree sync. What holds after
// it: SceneLights::set holds this frame's emissive triangles (in world
// space), enabled punctual lights and the environment; `version` increased
// exactly when the set was rebuilt this frame (a light, an emitter or the
// environment changed, or the geometry moved), `lighting_version` exactly
// when what lights the scene changed (not an object without emission that
// moved), `emitter_version` exactly when the emissive triangles changed (or
// may have: a material edit or new assets; not a moved sun or a brighter
// sky), and `geometry_version` exactly when the Embree scene changed, so
// per-frame caches (light probes) can tell which of their inputs moved.
#include "engine/app/app.h"
#include "engine/render/light_set.h"

namespace engine::render {

// How the light set is built. What a renderer that wants the sun as a
// directional light (the real-time paths) asks for.
struct LightSettings {
  // On = a sun found in the environment map is shaded as a directional light
  // of the disk's size (one shadow ray, no noise from finding it by chance),
  // at the cost of the disk's own shape (it becomes a uniform cone). Off =
  // the map lights as it is (the reference path tracer's default).
  bool split_sun = false;
  scene::SunExtractionSettings extraction;
};

struct SceneLights {
  LightSet set;
  std::uint64_t version = 0;           // the set was rebuilt (lighting or geometry changed)
  std::uint64_t lighting_version = 0;  // lights, emitters (moved too), environment or materials changed
  std::uint64_t emitter_version = 0;   // the emissive triangles (moved, edited, added or removed)
  std::uint64_t geometry_version = 0;  // the ray-traced geometry changed
  // The sun split of the current environment, computed once per map (a
  // moving object rebuilds the set every frame; the map does not change).
  std::shared_ptr<const scene::SunSplit> sun_split;
  const scene::Environment* sun_split_of = nullptr;
};

class LightPlugin final : public app::Plugin {
 public:
  void build(app::App& app) override;
  [[nodiscard]] std::string_view name() const override { return "engine::LightPlugin"; }
};

}  // namespace engine::render
