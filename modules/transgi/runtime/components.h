#pragma once
// The components a scene uses to get TransGI lighting.
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include <vector>

#include "model/transfer_model.h"
#include "probes/cascade_follow.h"
#include "probes/probe_field.h"

namespace transgi::runtime {

// The baked latents of one mesh instance. Pixels of entities without it skip
// inference and are shaded diffusely from the probes. Every LatentMesh of a
// scene shares one model (one scene decoder).
struct LatentMesh {
  std::shared_ptr<const model::TransferModel> model;
  std::uint32_t mesh = 0;  // model->meshes index; equals the entity's MeshInstance::mesh
};

// A grid of SH light probes. Set the bounds (or leave them empty to fit the
// scene's bounds when the volume is first updated) and the probe counts;
// the plugin owns `field`, the probes' state, and rebuilds it when these or
// the settings change.
struct ProbeVolume {
  glm::vec3 min{1.0f}, max{-1.0f};  // min > max: fit to the scene
  glm::ivec3 dims{8};
  // Where it meets another volume or the cascades, the band inside its faces
  // across which it hands over to them, in cells (cascades.h). Higher =
  // smoother seams, at the cost of two interpolations there.
  float blend_cells = 1.0f;

  std::shared_ptr<probes::ProbeField> field = nullptr;  // written by the plugin only
  [[nodiscard]] bool fits_scene() const { return glm::any(glm::greaterThan(min, max)); }
};

// Probes where the viewer is (probes/cascades.h): `cascades.count` grids of
// the same dims around the camera (GiFrame::camera, else the first camera),
// each twice the extent of the one before. They scroll by whole cells as the
// camera moves; the plugin owns `state.fields` (finest first) and rebuilds them
// when the settings change. A ProbeVolume with explicit bounds takes
// precedence over them inside it.
struct ProbeCascades {
  probes::CascadeSettings cascades;

  // Written by the plugin only: the fields, finest first (probes/cascade_follow.h).
  probes::CascadeState<probes::ProbeField> state{};
};

}  // namespace transgi::runtime
