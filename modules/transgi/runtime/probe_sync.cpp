#include "runtime/probe_sync.h"

#include <algorithm>
#include <cmath>

namespace transgi::runtime {

using namespace engine;
using namespace engine::schedule;

namespace {

struct SceneChanges {
  bool geometry_moved = false, lighting_changed = false, emitters_changed = false;
  const std::vector<rt::WorldBounds>* regions = nullptr;  // where geometry moved
};

SceneChanges changes_since(const SeenVersions& seen, const rt::RtScene& rt, const render::SceneLights& lights) {
  static const std::vector<rt::WorldBounds> kNothing;
  SceneChanges c;
  c.geometry_moved = lights.geometry_version != seen.geometry;
  c.lighting_changed = lights.lighting_version != seen.lights;
  c.emitters_changed = lights.emitter_version != seen.emitters;
  // Where it moved: probes there are updated first (RtScene keeps the list for its last commit).
  c.regions = c.geometry_moved ? &rt.changed_at_last_commit() : &kNothing;
  return c;
}

void tell(probes::ProbeField& field, const SceneChanges& c) {
  if (c.geometry_moved || c.lighting_changed)
    field.notify_scene_changed(
        {.geometry_moved = c.geometry_moved, .light_changed = c.lighting_changed, .emitters_changed = c.emitters_changed});
  for (const rt::WorldBounds& b : *c.regions) field.notify_region_changed(b.min, b.max);
}

}  // namespace

void sync_probe_volumes(View<Get<const scene::Camera, const transform::WorldTransform>> cameras, View<Get<ProbeVolume>> volumes,
                        Res<rt::RtScene> rt, Res<render::SceneLights> lights, Res<TransGISettings> settings, Res<GiFrame> frame,
                        Local<SeenVersions> seen) {
  const glm::vec3 eye = probes::viewer_of(cameras, frame->camera, rt->bounds_min(), rt->bounds_max()).sanitised().eye;
  const SceneChanges changes = changes_since(*seen, *rt, *lights);
  volumes.each([&](ProbeVolume& v) {
    if (v.fits_scene()) {
      // Fitted once: a later move must not shift every probe (and reset them).
      v.min = rt->bounds_min();
      v.max = rt->bounds_max();
    }
    probes::ProbeFieldSettings wanted = settings->probes;
    wanted.grid = probes::ProbeGrid::centred_in(v.min, v.max, v.dims);
    wanted.blend_cells = v.blend_cells;
    if (!v.field || !(v.field->settings() == wanted))
      v.field = std::make_shared<probes::ProbeField>(wanted);  // new: nothing to tell
    else
      tell(*v.field, changes);
    v.field->set_viewer(eye);
  });
  seen->geometry = lights->geometry_version;
  seen->lights = lights->lighting_version;
  seen->emitters = lights->emitter_version;
}

probes::ProbeFieldSettings cascade_field_settings(const probes::ProbeFieldSettings& base, const probes::CascadeSettings& c,
                                                  int k, const glm::ivec3& origin, GiPath path) {
  probes::ProbeFieldSettings s = base;
  s.grid = probes::cascade_grid(c, k, origin);
  s.update_budget = base.update_budget > 0 ? std::max(1, base.update_budget >> k) : 0;
  s.steady_light_budget = base.steady_light_budget > 0 ? std::max(1, base.steady_light_budget >> k) : 0;
  s.blend_cells = c.blend_cells;
  if (c.map_width > 0 && path == GiPath::Realtime) s.map = probes::MapLayout{c.map_width, std::max(2, c.map_width / 2)};
  return s;
}

void sync_probe_cascades(View<Get<const scene::Camera, const transform::WorldTransform>> cameras,
                         View<Get<ProbeCascades>> sets, Res<rt::RtScene> rt, Res<render::SceneLights> lights,
                         Res<TransGISettings> settings, ResMut<GiFrame> frame, Local<SeenVersions> seen) {
  const probes::CascadeViewer viewer = probes::viewer_of(cameras, frame->camera, rt->bounds_min(), rt->bounds_max());
  const SceneChanges changes = changes_since(*seen, *rt, *lights);
  int entered = 0;
  sets.each([&](ProbeCascades& set) {
    const probes::CascadeSettings& c = set.cascades;
    const auto wanted = [&](const probes::ProbeGrid& grid, int k) {
      probes::ProbeFieldSettings s = k >= 0 ? cascade_field_settings(settings->probes, c, k, glm::ivec3(0), settings->gi_path) : settings->probes;
      s.grid = grid;
      // The far field (k = count) lights only what no cascade holds.
      s.blend_cells = k >= std::max(1, c.count) ? probes::kFallbackBlendCells : c.blend_cells;
      // The fitted grid holds the region it was fitted to, up to its faces.
      if (k < 0) s.hold_cells = 0.5f;
      return s;
    };
    entered += probes::follow_camera(
        set.state, c, viewer, rt->bounds_min(), rt->bounds_max(), [&] { return probes::geometry_core(*rt); },
        [&](const probes::ProbeGrid& grid, int k) {
          auto f = std::make_shared<probes::ProbeField>(wanted(grid, k));
          if (k >= 0) f->set_focus(viewer.sanitised().eye);
          f->set_viewer(viewer.sanitised().eye);
          return f;
        },
        [&](const probes::ProbeField& f, const probes::ProbeGrid& grid, int k) { return f.settings() == wanted(grid, k); },
        [&](probes::ProbeField& f, glm::ivec3 cells, const probes::ProbeField* coarser) { return f.scroll(cells, coarser); },
        [&](probes::ProbeField& f, bool on_viewer) {
          tell(f, changes);
          if (on_viewer) f.set_focus(viewer.sanitised().eye);
          f.set_viewer(viewer.sanitised().eye);
        });
  });
  frame->cascade_probes_entered = entered;
  seen->geometry = lights->geometry_version;
  seen->lights = lights->lighting_version;
  seen->emitters = lights->emitter_version;
}

}  // namespace transgi::runtime
