#pragma once
// The components a scene uses to get TransGI lighting.
#include <cstdint>
#include <memory>

#include <glm/glm.hpp>

#include "model/transfer_model.h"
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

  std::shared_ptr<probes::ProbeField> field = nullptr;  // written by the plugin only
  [[nodiscard]] bool fits_scene() const { return glm::any(glm::greaterThan(min, max)); }
};

}  // namespace transgi::runtime
