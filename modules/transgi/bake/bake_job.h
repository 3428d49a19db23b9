#pragma once
// The whole bake, from loaded scene assets to a model file: dataset (cached
// next to the output so an interrupted bake does not trace again), training
// with periodic checkpoints (so --resume continues where it stopped), and
// the final model written atomically.
#include <filesystem>
#include <functional>
#include <string>

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
  bool dataset_from_cache = false;
  BandErrors validation, constant;
  std::size_t decoder_bytes = 0, latent_bytes = 0, latent_rows = 0;
  std::vector<std::pair<int, float>> loss_curve;  // (iteration, mean training L1 since the last entry)
  std::vector<std::pair<int, double>> validation_curve;
};

struct BakeCallbacks {
  std::function<void(std::size_t done, std::size_t total)> sampling;
  std::function<void(int iteration, int total, float loss)> training;
};

BakeReport run_bake(const engine::scene::SceneAssets& assets, const std::filesystem::path& out,
                    const BakeSettings& settings, const BakeCallbacks& callbacks = {});

std::filesystem::path dataset_cache_path(const std::filesystem::path& out);
std::filesystem::path checkpoint_path(const std::filesystem::path& out);

}  // namespace transgi::bake
