#pragma once
// Decoder variants for the ablation sweep (latent size, width, depth), each
// trained from one shared transfer dataset and cached on disk, keyed by the
// scene's fingerprint and the variant's settings, so repeated sweeps re-bake
// only what changed.
#include <filesystem>
#include <memory>
#include <string>

#include "bake/dataset.h"
#include "model/transfer_model.h"

namespace transgi::eval {

struct NetworkVariant {
  std::string name;  // e.g. "width 64"
  int latent_dim = 7;
  int width = 128;
  int depth = 3;  // hidden layers
};

class NetworkVariantBaker {
 public:
  NetworkVariantBaker(const engine::scene::SceneAssets& assets, std::uint64_t scene_fingerprint, bake::DatasetSettings data,
                      int iterations, std::filesystem::path cache_dir);
  // The trained variant (from the cache when there).
  std::shared_ptr<const model::TransferModel> get(const NetworkVariant& v);

 private:
  const engine::scene::SceneAssets& assets_;
  std::uint64_t fingerprint_;
  bake::DatasetSettings data_settings_;
  int iterations_;
  std::filesystem::path cache_dir_;
  std::unique_ptr<bake::TransferDataset> data_;  // generated on first need
};

}  // namespace transgi::eval
