#pragma once
// The whole bake, from loaded scene assets to a model file: dataset (cached
// next to the output so an interrupted bake does not trace again), training
// with periodic checkpoints (so --resume continues where it stopped), and
// the final model written atomically.
//
// On several ranks (a Communicator of size N, `mpirun -n N transgi bake`):
// each rank samples and caches its shard of the points, all train together
// (bake/trainer.h), rank 0 alone writes checkpoints and the model, and the
// callbacks run on rank 0 only, with every rank's rate.
#include <filesystem>
#include <functional>
#include <optional>
#include <span>
#include <string>

#include "bake/communicator.h"
#include "bake/dataset.h"
#include "bake/trainer.h"

namespace transgi::bake {

struct BakeSettings {
  DatasetSettings data;
  TrainSettings train;
  int latent_dim = 7;
  model::MlpLayout layout;       // inputs/outputs are derived
  int checkpoint_every = 500;    // iterations between checkpoints
  bool resume = false;
  bool keep_dataset = false;     // keep <out>.dataset after success
};

struct BakeReport {
  double data_seconds = 0, train_seconds = 0;
  std::size_t samples = 0, training_samples = 0, validation_samples = 0;
  int iterations = 0, resumed_from = 0, rollbacks = 0;
  bool dataset_from_cache = false;  // on every rank
  int ranks = 1;
  // This rank's training time split, and what it handed to the transport per
  // step (rank 0's numbers in the report the CLI prints).
  double compute_seconds = 0, exchange_seconds = 0;
  double bytes_sent_per_step = 0;
  std::vector<double> sampling_rates, training_rates;  // each rank's points/s and samples/s
  BandErrors validation, constant;
  std::size_t decoder_bytes = 0, latent_bytes = 0, latent_rows = 0;
  std::vector<std::pair<int, float>> loss_curve;  // (iteration, mean training L1 since the last entry)
  std::vector<std::pair<int, double>> validation_curve;
};

// Called on rank 0 only. rank_rates: each rank's points/s (sampling) or
// samples/s (training, refreshed every 100 steps; empty before the first).
struct BakeCallbacks {
  std::function<void(std::size_t done, std::size_t total, std::span<const double> rank_rates)> sampling;
  std::function<void(int iteration, int total, float loss, std::span<const double> rank_rates)> training;
};

BakeReport run_bake(const engine::scene::SceneAssets& assets, const std::filesystem::path& out,
                    const BakeSettings& settings, const BakeCallbacks& callbacks = {}, Communicator& comm = solo());

// Where rank `shard.rank` of `shard.count` caches its dataset: <out>.dataset
// alone, <out>.dataset.R-of-N on N ranks.
std::filesystem::path dataset_cache_path(const std::filesystem::path& out, DatasetShard shard = {});
std::filesystem::path checkpoint_path(const std::filesystem::path& out);
// The iteration of the checkpoint next to `out` where it is whole and belongs
// to these assets; nothing where it is absent or unusable (so --resume would
// start over).
std::optional<int> checkpoint_iteration(const std::filesystem::path& out, const engine::scene::SceneAssets& assets);

}  // namespace transgi::bake
