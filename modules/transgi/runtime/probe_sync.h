#pragma once
// The PrepareRender systems that keep each probe field placed and told of
// scene changes, for both kinds of volume: ProbeVolume (a fixed box, or the
// scene's bounds) and ProbeCascades (grids that follow the camera). And the
// order the renderer consults the fields in.
#include <vector>

#include "engine/render/light_plugin.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/schedule/system_param.h"
#include "engine/transform/transform.h"
#include "runtime/components.h"
#include "runtime/gi_frame.h"
#include "runtime/settings.h"

namespace transgi::runtime {

struct SeenVersions {
  std::uint64_t lights = 0, geometry = 0, emitters = 0;
};

// After it: every ProbeVolume has a field for the current settings and
// bounds (fitted to the scene once, if it has none); fields whose scene
// changed were told, so settled probes wake and moved geometry is
// reclassified; each field's viewer is the frame's camera.
void sync_probe_volumes(
    engine::schedule::View<engine::schedule::Get<const engine::scene::Camera, const engine::transform::WorldTransform>> cameras,
    engine::schedule::View<engine::schedule::Get<ProbeVolume>> volumes, engine::schedule::Res<engine::rt::RtScene> rt,
    engine::schedule::Res<engine::render::SceneLights> lights, engine::schedule::Res<TransGISettings> settings,
    engine::schedule::Res<GiFrame> frame, engine::schedule::Local<SeenVersions> seen);

// After it: every ProbeCascades has one field per cascade, centred on the
// camera; a field whose cascade origin moved has scrolled by whole cells
// (its entered slab seeded from the next coarser cascade, queued first) and
// its budget goes nearest the camera first; changes were told as above;
// each field's viewer is the camera.
void sync_probe_cascades(
    engine::schedule::View<engine::schedule::Get<const engine::scene::Camera, const engine::transform::WorldTransform>> cameras,
    engine::schedule::View<engine::schedule::Get<ProbeCascades>> sets, engine::schedule::Res<engine::rt::RtScene> rt,
    engine::schedule::Res<engine::render::SceneLights> lights, engine::schedule::Res<TransGISettings> settings,
    engine::schedule::ResMut<GiFrame> frame, engine::schedule::Local<SeenVersions> seen);

// A cascade's field settings: the run-time probe settings on cascade k's grid
// at `origin`, with its share of the budget and its blend band; on the
// real-time path, with the cascades' own (smaller) maps.
probes::ProbeFieldSettings cascade_field_settings(const probes::ProbeFieldSettings& base, const probes::CascadeSettings& c,
                                                  int k, const glm::ivec3& origin, GiPath path);

}  // namespace transgi::runtime
