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
#include "model/transfer_model.h"

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
  float visibility_fraction = model::kDefaultVisibilityFraction;
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

// Which of the bake's ranks samples (and trains on) which points.
struct DatasetShard {
  int rank = 0;
  int count = 1;
};

// A hash of the seed and a point's index over the whole scene. It decides
// which rank samples the point (shard_of_point) and which of the trainer's
// gradient blocks its samples fall in (TrainSettings::gradient_blocks): the
// same residue, so with N ranks and N dividing the block count, block b is
// rank b mod N's.
std::uint32_t point_hash(std::uint64_t seed, std::size_t point);

// The rank that owns a point: point_hash mod the rank count, so the points,
// their rays and their targets are the same whatever the number of ranks;
// only who computes them changes.
int shard_of_point(std::uint64_t seed, std::size_t point, int shard_count);

// A rank's share of the training data (with one rank: all of it).
struct TransferDataset {
  // Whether the targets are demodulated (DatasetSettings::demodulate); a
  // model trained on them is (Trainer sets TransferModel::demodulated).
  bool demodulated = false;
  std::vector<TransferSample> samples;  // training samples first, then validation
  std::vector<float> targets;           // kTransferValues per sample
  std::size_t training_count = 0;
  double seconds = 0;
  // The training points' ordinals among every rank's training points (the
  // one-process dataset's order), ascending, `outgoing` samples each: the
  // trainer draws each batch from all ranks' samples alike and each rank
  // computes the ones it holds, so the batches do not depend on the rank count.
  std::vector<std::uint64_t> training_points;
  std::vector<std::uint32_t> training_point_hashes;  // point_hash of each, in the same order
  std::uint64_t all_training_samples = 0;  // over every rank
  int outgoing = 1;
  DatasetShard shard;  // whose share this is

  [[nodiscard]] const float* target(std::size_t i) const { return targets.data() + i * kTransferValues; }
  [[nodiscard]] std::size_t validation_count() const { return samples.size() - training_count; }
  // The local index of the sample with this ordinal among all ranks'
  // training samples, or -1 where another rank holds it.
  [[nodiscard]] std::int64_t local_training_sample(std::uint64_t global) const;
};

// Points per mesh: area[m] / total of `points`, at least min_points_per_mesh
// (where area > 0), at most max_points_per_vertex x vertices[m], what a cap
// frees shared among the other meshes by area (water-filling).
std::vector<int> points_per_mesh(const std::vector<double>& area, const std::vector<std::size_t>& vertices,
                                 const DatasetSettings& settings);

// The points are traced in kSamplingRounds rounds of equal shares of the
// scene's points; progress(points_done, points_total) is called on the
// calling thread after each, for this shard's points, on every rank alike (so
// a caller can exchange progress between ranks there). Deterministic for a
// seed, whatever the thread count and the shard count.
inline constexpr int kSamplingRounds = 100;
TransferDataset generate_dataset(const engine::scene::SceneAssets& assets, const DatasetSettings& settings,
                                 const std::function<void(std::size_t, std::size_t)>& progress = {},
                                 DatasetShard shard = {});

}  // namespace transgi::bake
