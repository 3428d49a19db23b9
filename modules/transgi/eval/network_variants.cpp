#include "eval/network_variants.h"

#include <nlohmann/json.hpp>

#include <cstdio>

#include "bake/trainer.h"
#include "engine/core/fnv1a.h"
#include "engine/core/progress.h"
#include "eval/scene_fingerprint.h"
#include "model/model_file.h"

namespace transgi::eval {

NetworkVariantBaker::NetworkVariantBaker(const engine::scene::SceneAssets& assets, std::uint64_t scene_fingerprint,
                                         bake::DatasetSettings data, int iterations, std::filesystem::path cache_dir)
    : assets_(assets), fingerprint_(scene_fingerprint), data_settings_(data), iterations_(iterations), cache_dir_(std::move(cache_dir)) {}

std::shared_ptr<const model::TransferModel> NetworkVariantBaker::get(const NetworkVariant& v) {
  engine::core::Fnv1a key;
  for (std::uint64_t x : {fingerprint_, static_cast<std::uint64_t>(v.latent_dim), static_cast<std::uint64_t>(v.width),
                          static_cast<std::uint64_t>(v.depth), static_cast<std::uint64_t>(iterations_),
                          static_cast<std::uint64_t>(data_settings_.points), static_cast<std::uint64_t>(data_settings_.rays),
                          data_settings_.seed})
    key.value(x);
  const auto path = cache_dir_ / ("network-" + hex64(key.h) + ".tgm");
  if (std::filesystem::exists(path)) {
    try {
      auto m = model::load_model(path);
      return std::make_shared<const model::TransferModel>(std::move(m));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "warning: re-baking %s: %s\n", path.string().c_str(), e.what());
    }
  }
  if (!data_) {
    std::unique_ptr<engine::core::ProgressBar> bar;
    data_ = std::make_unique<bake::TransferDataset>(bake::generate_dataset(assets_, data_settings_, [&](std::size_t done, std::size_t total) {
      if (!bar) bar = std::make_unique<engine::core::ProgressBar>("sweep dataset", total);
      bar->update(done);
      if (done == total) bar->finish();
    }));
  }
  auto m = bake::make_untrained_model(assets_, v.latent_dim, model::MlpLayout{.width = v.width, .hidden_layers = v.depth}, 1);
  bake::TrainSettings ts;
  ts.iterations = iterations_;
  bake::Trainer trainer(*data_, assets_, m, ts);
  engine::core::ProgressBar bar("bake " + v.name, static_cast<std::uint64_t>(iterations_));
  for (int i = 0; i < iterations_; ++i) {
    trainer.step();
    if ((i + 1) % 100 == 0 || i + 1 == iterations_) bar.update(static_cast<std::uint64_t>(i + 1));
  }
  const bake::BandErrors val = trainer.validate();
  bar.finish("validation RMSE " + std::to_string(val.total));
  m.bake_settings_json =
      nlohmann::json{{"variant", v.name}, {"iterations", iterations_}, {"points", data_settings_.points}, {"rays", data_settings_.rays}}.dump();
  m.metrics_json = nlohmann::json{{"validation_rmse", val.total}}.dump();
  std::filesystem::create_directories(cache_dir_);
  model::save_model(path, m);
  return std::make_shared<const model::TransferModel>(std::move(m));
}

}  // namespace transgi::eval
