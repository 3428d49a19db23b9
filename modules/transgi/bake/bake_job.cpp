#include "bake/bake_job.h"

#include <chrono>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "engine/io/atomic_file.h"
#include "model/model_file.h"

namespace transgi::bake {

namespace fs = std::filesystem;

fs::path dataset_cache_path(const fs::path& out) { return fs::path(out.string() + ".dataset"); }
fs::path checkpoint_path(const fs::path& out) { return fs::path(out.string() + ".ckpt"); }

namespace {

std::uint64_t fnv(const void* p, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  const auto* c = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  return h;
}

// Identifies a dataset: every mesh's content and every sampling setting.
std::uint64_t dataset_key(const engine::scene::SceneAssets& assets, const DatasetSettings& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint32_t m = 0; m < assets.meshes.size(); ++m) {
    const std::uint64_t mh = model::mesh_content_hash(assets, m);
    h = fnv(&mh, sizeof(mh), h);
  }
  const double fields[] = {double(s.points), double(s.min_points_per_mesh), double(s.outgoing_per_point), double(s.rays),
                           double(s.visibility_fraction), double(s.validation_fraction), double(s.seed),
                           double(s.max_points_per_vertex), double(s.demodulate ? 1 : 0)};
  return fnv(fields, sizeof(fields), h);
}

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
void put_vec(std::string& out, const std::vector<T>& v) {
  put<std::uint64_t>(out, v.size());
  out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}
template <class T>
bool get(std::istream& in, T& v) {
  return static_cast<bool>(in.read(reinterpret_cast<char*>(&v), sizeof(T)));
}
template <class T>
bool get_vec(std::istream& in, std::vector<T>& v, std::uint64_t max_count) {
  std::uint64_t n = 0;
  if (!get(in, n) || n > max_count) return false;
  v.resize(n);
  return static_cast<bool>(in.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(T))));
}

void save_dataset(const fs::path& p, std::uint64_t key, const TransferDataset& d) {
  std::string out = "TGD1";
  put(out, key);
  put<std::uint64_t>(out, d.training_count);
  put(out, d.seconds);
  put_vec(out, d.samples);
  put_vec(out, d.targets);
  put(out, fnv(out.data(), out.size()));
  engine::io::write_file_atomically(p, std::as_bytes(std::span(out.data(), out.size())));
}

// Reads a file written as magic + body + FNV-1a of both; returns the body,
// or nothing if the file is missing, foreign or damaged.
std::optional<std::string> read_checked(const fs::path& p, const char* magic) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return std::nullopt;
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 12 || bytes.compare(0, 4, magic) != 0) return std::nullopt;
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (fnv(bytes.data(), bytes.size() - 8) != stored) return std::nullopt;
  return bytes.substr(4, bytes.size() - 12);
}

// A cache that is missing, damaged or for other inputs is simply not used.
bool load_dataset(const fs::path& p, std::uint64_t key, TransferDataset& d) {
  const auto body = read_checked(p, "TGD1");
  if (!body) return false;
  std::istringstream s(*body);
  std::uint64_t k = 0, training = 0;
  if (!get(s, k) || k != key || !get(s, training) || !get(s, d.seconds)) return false;
  if (!get_vec(s, d.samples, 1ull << 32) || !get_vec(s, d.targets, 1ull << 36)) return false;
  d.training_count = training;
  return d.targets.size() == d.samples.size() * kTransferValues && training <= d.samples.size();
}

void save_checkpoint(const fs::path& out, const model::TransferModel& m, const Trainer::State& st) {
  model::save_model(checkpoint_path(out), m);
  std::string s = "TGC1";
  put(s, st.iteration);
  put(s, st.lr_scale);
  put(s, st.rollbacks);
  put_vec(s, st.m);
  put_vec(s, st.v);
  put(s, fnv(s.data(), s.size()));
  engine::io::write_file_atomically(fs::path(checkpoint_path(out).string() + ".state"), std::as_bytes(std::span(s.data(), s.size())));
}

bool load_checkpoint(const fs::path& out, const engine::scene::SceneAssets& assets, model::TransferModel& m,
                     Trainer::State& st) {
  try {
    model::TransferModel loaded = model::load_model(checkpoint_path(out));
    model::validate_model(loaded, assets, checkpoint_path(out));
    if (!(loaded.decoder.layout() == m.decoder.layout()) || loaded.latent_dim != m.latent_dim) return false;
    const auto body = read_checked(checkpoint_path(out).string() + ".state", "TGC1");
    if (!body) return false;
    std::istringstream s(*body);
    if (!get(s, st.iteration) || !get(s, st.lr_scale) || !get(s, st.rollbacks) || !get_vec(s, st.m, 1ull << 32) ||
        !get_vec(s, st.v, 1ull << 32))
      return false;
    m = std::move(loaded);
    return true;
  } catch (const std::exception&) {
    return false;  // an unusable checkpoint means starting over, not failing
  }
}


}  // namespace

BakeReport run_bake(const engine::scene::SceneAssets& assets, const fs::path& out, const BakeSettings& s,
                    const BakeCallbacks& cb) {
  BakeReport report;
  const std::uint64_t key = dataset_key(assets, s.data);
  TransferDataset data;
  const auto t0 = std::chrono::steady_clock::now();
  if (s.resume && load_dataset(dataset_cache_path(out), key, data)) {
    report.dataset_from_cache = true;
    data.demodulated = s.data.demodulate;  // part of the cache's key
  } else {
    data = generate_dataset(assets, s.data, cb.sampling);
    save_dataset(dataset_cache_path(out), key, data);
  }
  report.data_seconds = report.dataset_from_cache ? data.seconds : std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  report.samples = data.samples.size();
  report.training_samples = data.training_count;
  report.validation_samples = data.validation_count();

  model::TransferModel m = make_untrained_model(assets, s.latent_dim, s.layout, s.train.seed);
  Trainer::State state;
  const bool resumed = s.resume && load_checkpoint(out, assets, m, state);
  Trainer trainer(data, assets, m, s.train);
  if (resumed) {
    trainer.restore(state);
    report.resumed_from = state.iteration;
  }
  report.constant = trainer.constant_predictor();

  const auto t1 = std::chrono::steady_clock::now();
  double loss_sum = 0;
  int loss_n = 0;
  while (trainer.iteration() < s.train.iterations) {
    const float loss = trainer.step();
    loss_sum += loss;
    ++loss_n;
    const int it = trainer.iteration();
    if (cb.training) cb.training(it, s.train.iterations, loss);
    if (it % 100 == 0 && loss_n > 0) {
      report.loss_curve.emplace_back(it, static_cast<float>(loss_sum / loss_n));
      loss_sum = 0;
      loss_n = 0;
    }
    if (it % 1000 == 0) report.validation_curve.emplace_back(it, trainer.validate().total);
    if (s.checkpoint_every > 0 && it % s.checkpoint_every == 0 && it < s.train.iterations) save_checkpoint(out, m, trainer.state());
  }
  report.train_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  report.iterations = trainer.iteration();
  report.rollbacks = trainer.rollbacks();
  report.validation = trainer.validate();
  report.decoder_bytes = m.decoder_bytes();
  report.latent_bytes = m.latent_bytes();
  for (const auto& mesh : m.meshes) report.latent_rows += mesh.latents.rows();

  const auto& l = m.decoder.layout();
  const auto bands = [](const BandErrors& e) { return nlohmann::json(std::vector<double>(e.rmse.begin(), e.rmse.end())); };
  m.bake_settings_json = nlohmann::json{{"points", s.data.points},
                                        {"outgoing_per_point", s.data.outgoing_per_point},
                                        {"rays", s.data.rays},
                                        {"visibility_fraction", s.data.visibility_fraction},
                                        {"iterations", s.train.iterations},
                                        {"batch", s.train.batch},
                                        {"learning_rate", s.train.learning_rate},
                                        {"latent_dim", s.latent_dim},
                                        {"width", l.width},
                                        {"hidden_layers", l.hidden_layers},
                                        {"seed", s.data.seed},
                                        {"demodulated", s.data.demodulate}}
                             .dump();
  m.metrics_json = nlohmann::json{{"data_seconds", report.data_seconds},
                                  {"train_seconds", report.train_seconds},
                                  {"samples", report.samples},
                                  {"rollbacks", report.rollbacks},
                                  {"validation_rmse", report.validation.total},
                                  {"validation_rmse_per_band", bands(report.validation)},
                                  {"constant_rmse_per_band", bands(report.constant)}}
                       .dump();
  model::save_model(out, m);

  std::error_code ec;
  fs::remove(checkpoint_path(out), ec);
  fs::remove(checkpoint_path(out).string() + ".state", ec);
  if (!s.keep_dataset) fs::remove(dataset_cache_path(out), ec);
  return report;
}

}  // namespace transgi::bake
