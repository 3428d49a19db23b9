#include "runtime/probe_sync.h"

#include <algorithm>
#include <cmath>

namespace transgi::runtime {

using namespace engine;
using namespace engine::schedule;

namespace {

struct SceneChanges {
  bool geometry_moved = false, lighting_changed = false;
  const std::vector<rt::WorldBounds>* regions = nullptr;  // where geometry moved
};

SceneChanges changes_since(const SeenVersions& seen, const rt::RtScene& rt, const render::SceneLights& lights) {
  static const std::vector<rt::WorldBounds> kNothing;
  SceneChanges c;
  c.geometry_moved = lights.geometry_version != seen.geometry;
  c.lighting_changed = lights.version != seen.lights;
  // Where it moved: probes there are updated first (RtScene keeps the list for its last commit).
  c.regions = c.geometry_moved ? &rt.changed_at_last_commit() : &kNothing;
  return c;
}

void tell(probes::ProbeField& field, const SceneChanges& c) {
  if (c.geometry_moved || c.lighting_changed) field.notify_scene_changed(c.geometry_moved);
  for (const rt::WorldBounds& b : *c.regions) field.notify_region_changed(b.min, b.max);
}

}  // namespace

void sync_probe_volumes(View<Get<ProbeVolume>> volumes, Res<rt::RtScene> rt, Res<render::SceneLights> lights,
                        Res<TransGISettings> settings, Local<SeenVersions> seen) {
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
    if (!v.field || !(v.field->settings() == wanted)) {
      v.field = std::make_shared<probes::ProbeField>(wanted);
      return;
    }
    tell(*v.field, changes);
  });
  seen->geometry = lights->geometry_version;
  seen->lights = lights->version;
}

probes::ProbeFieldSettings cascade_field_settings(const probes::ProbeFieldSettings& base, const probes::CascadeSettings& c,
                                                  int k, const glm::ivec3& origin) {
  probes::ProbeFieldSettings s = base;
  s.grid = probes::cascade_grid(c, k, origin);
  s.update_budget = base.update_budget > 0 ? std::max(1, base.update_budget >> k) : 0;
  s.blend_cells = c.blend_cells;
  return s;
}

void sync_probe_cascades(View<Get<const scene::Camera, const transform::WorldTransform>> cameras,
                         View<Get<ProbeCascades>> sets, Res<rt::RtScene> rt, Res<render::SceneLights> lights,
                         Res<TransGISettings> settings, ResMut<GiFrame> frame, Local<SeenVersions> seen) {
  // The eye: the frame's camera, else the first; with none, the scene's centre.
  bool have_eye = false;
  glm::vec3 eye = 0.5f * (rt->bounds_min() + rt->bounds_max()), forward(0.0f);
  cameras.each([&](ecs::Entity e, const scene::Camera&, const transform::WorldTransform& w) {
    if (!have_eye || e == frame->camera) {
      eye = w.translation;
      forward = w.rotation * glm::vec3(0.0f, 0.0f, -1.0f);  // glTF cameras look down -z
    }
    have_eye = true;
  });
  if (!(glm::dot(forward, forward) > 0.5f && glm::dot(forward, forward) < 2.0f)) forward = glm::vec3(0.0f);
  // Cell indices must fit an int whatever a script does to the camera.
  if (!std::isfinite(eye.x) || !std::isfinite(eye.y) || !std::isfinite(eye.z)) eye = glm::vec3(0.0f);
  eye = glm::clamp(eye, glm::vec3(-1e6f), glm::vec3(1e6f));
  const SceneChanges changes = changes_since(*seen, *rt, *lights);
  int entered = 0;
  sets.each([&](ProbeCascades& set) {
    const probes::CascadeSettings& c = set.cascades;
    // A small scene: one grid over its bounds, decided and fitted once (as
    // sync_probe_volumes does), so a later move does not reset every probe.
    const glm::vec3 extent = rt->bounds_max() - rt->bounds_min();
    const float cell = std::max({extent.x, extent.y, extent.z}) / static_cast<float>(std::max({c.dims.x, c.dims.y, c.dims.z, 1}));
    if (set.fields.empty() && c.fit_scene_cell > 0 && std::isfinite(cell) && cell <= c.fit_scene_cell) {
      probes::ProbeFieldSettings wanted = settings->probes;
      wanted.grid = probes::ProbeGrid::centred_in(rt->bounds_min(), rt->bounds_max(), c.dims);
      wanted.blend_cells = c.blend_cells;
      set.fields = {std::make_shared<probes::ProbeField>(wanted)};
      set.origins = {glm::ivec3(0)};
      set.fitted_to_scene = true;
      return;
    }
    if (set.fitted_to_scene) {
      probes::ProbeFieldSettings wanted = settings->probes;
      wanted.grid = set.fields[0]->settings().grid;
      wanted.blend_cells = c.blend_cells;
      if (!(wanted == set.fields[0]->settings())) set.fields[0] = std::make_shared<probes::ProbeField>(wanted);
      else tell(*set.fields[0], changes);
      return;
    }
    const int n = std::max(1, c.count);
    set.fields.resize(static_cast<std::size_t>(n));
    set.origins.resize(static_cast<std::size_t>(n));
    // Coarsest first: a finer cascade's entered slab is seeded from a coarser
    // one that has already moved.
    for (int k = n - 1; k >= 0; --k) {
      auto& field = set.fields[static_cast<std::size_t>(k)];
      glm::ivec3& origin = set.origins[static_cast<std::size_t>(k)];
      const glm::ivec3 wanted_origin = probes::cascade_origin(c, k, eye, forward);
      probes::ProbeFieldSettings wanted = cascade_field_settings(settings->probes, c, k, wanted_origin);
      if (field) {
        // Equal but for where it stands: scroll it; anything else: rebuild.
        const probes::ProbeGrid& now = field->settings().grid;
        probes::ProbeFieldSettings placed = wanted;
        placed.grid = now;
        if (!(placed == field->settings()) || now.dims != wanted.grid.dims || now.spacing() != wanted.grid.spacing())
          field.reset();
      }
      if (!field) {
        field = std::make_shared<probes::ProbeField>(wanted);
        origin = wanted_origin;
      } else {
        const probes::ProbeField* coarser = k + 1 < n ? set.fields[static_cast<std::size_t>(k + 1)].get() : nullptr;
        entered += field->scroll(wanted_origin - origin, coarser);
        origin = wanted_origin;
        tell(*field, changes);
      }
      field->set_focus(eye);
    }
  });
  frame->cascade_probes_entered = entered;
  seen->geometry = lights->geometry_version;
  seen->lights = lights->version;
}

}  // namespace transgi::runtime
