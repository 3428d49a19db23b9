#pragma once
// Training data for the neural transfer model: surface points sampled by
// area over every mesh, each with several outgoing directions and their
// ground-truth transfer (bake/transfer.h). Points, not samples, are split
// into training and validation, so no validation target shares rays with a
// training target.
#include <cstdint>
#include <functional>
#include <vector>

#include <glm/glm.hpp>

#include "bake/transfer.h"

namespace transgi::bake {

struct DatasetSettings {
  // Surface points over the whole scene, split between meshes by area. Higher
  // = better coverage of the transfer function, at the cost of bake time.
  int points = 32768;
  // Every mesh gets at least this many points, so small objects are learned too.
  int min_points_per_mesh = 32;
  // ... and at most this many per vertex (its latents), the rest going to the
  // other meshes by area: a 200 m ground plane of 4 vertices would otherwise
  // take nearly every point from the building on it. Higher = big, coarsely
  // tessellated meshes get more, at the cost of the detailed ones; 0 = by
  // area alone. 8192 changes none of our scenes' bakes (the most any mesh
  // gets is 4,798 a vertex: a 140 m^2 quad in the Breakfast Room).
  int max_points_per_vertex = 8192;
  // Outgoing directions per point; they share the point's rays. Higher = more
  // view-dependence per traced ray, at the cost of fewer distinct points.
  int outgoing_per_point = 8;
  // Rays per point (the paper uses 2000). Higher = less noisy targets, at the cost of time.
  int rays = 2000;
  // Visibility distance t as a fraction of each mesh's bounding-box diagonal.
  float visibility_fraction = 0.5f;
  float validation_fraction = 0.05f;
  std::uint64_t seed = 1;
  // Targets divided by each point's base colour (model::demodulation): the
  // network learns light, and shading multiplies the pixel's own base colour
  // back, so textures and hues are exact in the GI (issue 37). Off = the
  // paper's transfer, albedo included.
  bool demodulate = true;
};

struct TransferSample {
  std::uint32_t mesh = 0;
  std::uint32_t triangle = 0;
  glm::vec2 barycentric{0.0f};
  glm::vec3 normal{0.0f};  // object space, unit
  glm::vec3 wo{0.0f};      // object space, unit
  glm::vec3 albedo{0.0f};
};

struct TransferDataset {
  // Whether the targets are demodulated (DatasetSettings::demodulate); a
  // model trained on them is (Trainer sets TransferModel::demodulated).
  bool demodulated = false;
  std::vector<TransferSample> samples;  // training samples first, then validation
  std::vector<float> targets;           // kTransferValues per sample
  std::size_t training_count = 0;
  double seconds = 0;

  [[nodiscard]] const float* target(std::size_t i) const { return targets.data() + i * kTransferValues; }
  [[nodiscard]] std::size_t validation_count() const { return samples.size() - training_count; }
};

// Points per mesh: area[m] / total of `points`, at least min_points_per_mesh
// (where area > 0), at most max_points_per_vertex x vertices[m], what a cap
// frees shared among the other meshes by area (water-filling).
std::vector<int> points_per_mesh(const std::vector<double>& area, const std::vector<std::size_t>& vertices,
                                 const DatasetSettings& settings);

// progress(points_done, points_total). Deterministic for a seed, whatever the thread count.
TransferDataset generate_dataset(const engine::scene::SceneAssets& assets, const DatasetSettings& settings,
                                 const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace transgi::bake
