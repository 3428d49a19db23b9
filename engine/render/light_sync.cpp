#include "engine/render/light_plugin.h"
#include "engine/rt/rt_plugin.h"
#include "engine/transform/transform.h"

namespace engine::render {

namespace {

using namespace engine::schedule;
using LightView = View<Get<const scene::PunctualLight, const transform::WorldTransform>>;

// Whether two sets hold the same emissive triangles: a moved object that
// emits nothing leaves them as they were.
bool same_emitters(const LightSet& a, const LightSet& b) {
  const std::vector<EmissiveTriangle>& x = a.emissive_triangles();
  const std::vector<EmissiveTriangle>& y = b.emissive_triangles();
  if (x.size() != y.size()) return false;
  for (std::size_t i = 0; i < x.size(); ++i)
    if (x[i].p0 != y[i].p0 || x[i].p1 != y[i].p1 || x[i].p2 != y[i].p2 || x[i].material != y[i].material ||
        x[i].emission != y[i].emission)
      return false;
  return true;
}

struct SeenState {
  std::uint64_t commits = UINT64_MAX;  // RtScene top-level commits at the last rebuild
  std::uint64_t assets_generation = UINT64_MAX;
  bool split_sun = false;
  std::uint64_t edit_version = 0;  // SceneAssets::edit_version at the last rebuild
};

void sync_lights(LightView lights, Removed<scene::PunctualLight> removed, Res<rt::RtScene> rt, Res<LightSettings> settings,
                 ResMut<SceneLights> out, Local<SeenState> seen) {
  bool lights_changed = !removed.empty() || settings->split_sun != seen->split_sun;
  std::vector<PunctualInstance> punctual;
  lights.each([&](Entity e, const scene::PunctualLight& l, const transform::WorldTransform& w) {
    if (lights.is_changed<scene::PunctualLight>(e) || lights.is_changed<transform::WorldTransform>(e)) lights_changed = true;
    if (auto p = render::punctual_instance(l, w)) punctual.push_back(*p);
  });
  const scene::SceneAssets* assets = rt->assets();
  const std::uint64_t generation = assets ? assets->generation : 0;
  const bool geometry_changed = rt->stats().top_level_commits != seen->commits;
  const bool edited = assets && assets->edit_version != seen->edit_version;
  const bool assets_changed = generation != seen->assets_generation;
  lights_changed = lights_changed || edited;
  if (!lights_changed && !geometry_changed && !assets_changed) return;
  // Emissive triangles are stored in world space, so moved geometry also
  // means a rebuilt light set.
  const scene::Environment* env = assets && assets->environment ? &*assets->environment : nullptr;
  if (!settings->split_sun || !env) {
    out->sun_split.reset();
    out->sun_split_of = nullptr;
  } else if (out->sun_split_of != env || assets_changed || edited || !out->sun_split) {
    out->sun_split = std::make_shared<const scene::SunSplit>(scene::split_sun(*env, settings->extraction));
    out->sun_split_of = env;
  }
  LightSet set(*rt, std::move(punctual), env, out->sun_split);
  const bool emitters_changed = assets_changed || edited || !same_emitters(out->set, set);
  if (lights_changed || emitters_changed) ++out->lighting_version;
  if (emitters_changed) ++out->emitter_version;
  out->set = std::move(set);
  ++out->version;
  if (geometry_changed || assets_changed) ++out->geometry_version;
  seen->commits = rt->stats().top_level_commits;
  seen->assets_generation = generation;
  seen->split_sun = settings->split_sun;
  seen->edit_version = assets ? assets->edit_version : 0;
}

}  // namespace

void LightPlugin::build(app::App& app) {
  app.add_plugin<rt::RtPlugin>();  // the Embree mirror this sync runs after
  if (!app.world().has_resource<SceneLights>()) app.world().insert_resource<SceneLights>();
  if (!app.world().has_resource<LightSettings>()) app.world().insert_resource<LightSettings>();
  app.add_system(Phase::PrepareRender, "render::sync_lights", sync_lights);
}

}  // namespace engine::render
