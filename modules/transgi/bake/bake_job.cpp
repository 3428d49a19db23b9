#include "bake/bake_job.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "engine/io/atomic_file.h"
#include "model/model_file.h"

namespace transgi::bake {

namespace fs = std::filesystem;

fs::path dataset_cache_path(const fs::path& out, DatasetShard shard) {
  if (shard.count <= 1) return fs::path(out.string() + ".dataset");
  return fs::path(out.string() + ".dataset." + std::to_string(shard.rank) + "-of-" + std::to_string(shard.count));
}
fs::path checkpoint_path(const fs::path& out) { return fs::path(out.string() + ".ckpt"); }

namespace {

std::uint64_t fnv(const void* p, std::size_t n, std::uint64_t h = 1469598103934665603ull) {
  const auto* c = static_cast<const unsigned char*>(p);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  return h;
}

// Identifies a dataset: every mesh's content and every sampling setting.
std::uint64_t dataset_key(const engine::scene::SceneAssets& assets, const DatasetSettings& s, DatasetShard shard) {
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint32_t m = 0; m < assets.meshes.size(); ++m) {
    const std::uint64_t mh = model::mesh_content_hash(assets, m);
    h = fnv(&mh, sizeof(mh), h);
  }
  const double fields[] = {double(s.points), double(s.min_points_per_mesh), double(s.outgoing_per_point), double(s.rays),
                           double(s.visibility_fraction), double(s.validation_fraction), double(s.seed),
                           double(s.max_points_per_vertex), double(s.demodulate ? 1 : 0), double(shard.rank),
                           double(shard.count)};
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
  std::string out = "TGD3";
  put(out, key);
  put<std::uint64_t>(out, d.training_count);
  put(out, d.seconds);
  put<std::uint64_t>(out, d.all_training_samples);
  put<std::int32_t>(out, d.outgoing);
  put_vec(out, d.training_points);
  put_vec(out, d.training_point_hashes);
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
  const auto body = read_checked(p, "TGD3");
  if (!body) return false;
  std::istringstream s(*body);
  std::uint64_t k = 0, training = 0;
  if (!get(s, k) || k != key || !get(s, training) || !get(s, d.seconds) || !get(s, d.all_training_samples) ||
      !get(s, d.outgoing) || d.outgoing < 1)
    return false;
  if (!get_vec(s, d.training_points, 1ull << 36) || !get_vec(s, d.training_point_hashes, 1ull << 36) ||
      !get_vec(s, d.samples, 1ull << 36) || !get_vec(s, d.targets, 1ull << 40))
    return false;
  d.training_count = training;
  return d.targets.size() == d.samples.size() * kTransferValues && training <= d.samples.size() &&
         training == d.training_points.size() * static_cast<std::uint64_t>(d.outgoing) &&
         d.training_point_hashes.size() == d.training_points.size();
}

// The optimiser's state and the model in one file, written atomically, so a
// kill at any moment leaves the previous checkpoint or this one, never a
// model of one step with the moments of another.
void save_checkpoint(const fs::path& out, const model::TransferModel& m, const Trainer::State& st) {
  std::string s = "TGC2";
  put(s, st.iteration);
  put(s, st.lr_scale);
  put(s, st.rollbacks);
  put_vec(s, st.m);
  put_vec(s, st.v);
  put_vec(s, model::encode_model(m));
  put(s, fnv(s.data(), s.size()));
  engine::io::write_file_atomically(checkpoint_path(out), std::as_bytes(std::span(s.data(), s.size())));
}

// The checkpoint's state and model, if it is whole and belongs to these assets.
std::optional<std::pair<Trainer::State, model::TransferModel>> read_checkpoint(const fs::path& out,
                                                                               const engine::scene::SceneAssets& assets) {
  try {
    const auto body = read_checked(checkpoint_path(out), "TGC2");
    if (!body) return std::nullopt;
    std::istringstream s(*body);
    Trainer::State st;
    std::vector<std::byte> model_bytes;
    if (!get(s, st.iteration) || !get(s, st.lr_scale) || !get(s, st.rollbacks) || !get_vec(s, st.m, 1ull << 36) ||
        !get_vec(s, st.v, 1ull << 36) || !get_vec(s, model_bytes, 1ull << 40))
      return std::nullopt;
    model::TransferModel loaded = model::decode_model(model_bytes, checkpoint_path(out).string());
    model::validate_model(loaded, assets, checkpoint_path(out));
    return std::make_pair(std::move(st), std::move(loaded));
  } catch (const std::exception&) {
    return std::nullopt;  // an unusable checkpoint means starting over, not failing
  }
}

bool load_checkpoint(const fs::path& out, const engine::scene::SceneAssets& assets, model::TransferModel& m,
                     Trainer::State& st) {
  auto read = read_checkpoint(out, assets);
  if (!read || !(read->second.decoder.layout() == m.decoder.layout()) || read->second.latent_dim != m.latent_dim) return false;
  st = std::move(read->first);
  m = std::move(read->second);
  return true;
}

// A hash of the model's weights: the ranks' replicas must agree.
std::uint64_t weights_hash(const model::TransferModel& m) {
  std::uint64_t h = fnv(m.decoder.params().data(), m.decoder.params().size() * sizeof(float));
  for (const auto& mesh : m.meshes) h = fnv(mesh.latents.values.data(), mesh.latents.values.size() * sizeof(float), h);
  return h;
}

bool all_equal(const std::vector<std::uint64_t>& v) { return std::adjacent_find(v.begin(), v.end(), std::not_equal_to<>()) == v.end(); }

struct RankProgress {
  double done = 0, total = 0, seconds = 0;
};

// Stage 1: this rank's shard of the dataset, from its cache or traced. Every
// rank passes the same kSamplingRounds progress exchanges, a cached one with
// nothing left to do, so the ranks' calls stay matched.
TransferDataset shard_dataset(const engine::scene::SceneAssets& assets, const fs::path& out, const BakeSettings& s,
                              const BakeCallbacks& cb, Communicator& comm, BakeReport& report) {
  const DatasetShard shard{comm.rank(), comm.size()};
  const std::uint64_t key = dataset_key(assets, s.data, shard);
  TransferDataset data;
  const bool cached = s.resume && load_dataset(dataset_cache_path(out, shard), key, data);
  data.shard = shard;  // part of the cache's key
  if (cached) data.demodulated = s.data.demodulate;  // part of the cache's key
  const auto flags = gather_each(comm, std::uint64_t{cached ? 1u : 0u});
  report.dataset_from_cache = std::all_of(flags.begin(), flags.end(), [](std::uint64_t f) { return f == 1; });
  if (report.dataset_from_cache) return data;

  const auto t0 = std::chrono::steady_clock::now();
  const auto round_done = [&](std::size_t done, std::size_t total) {
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto all = gather_each(comm, RankProgress{double(done), double(total), seconds});
    if (comm.rank() != 0 || !cb.sampling) return;
    double all_done = 0, all_total = 0;
    std::vector<double> rates;
    for (const RankProgress& p : all) {
      all_done += p.done;
      all_total += p.total;
      rates.push_back(p.seconds > 0 ? p.done / p.seconds : 0.0);
    }
    cb.sampling(static_cast<std::size_t>(all_done), static_cast<std::size_t>(all_total), rates);
  };
  if (cached) {
    for (int round = 0; round < kSamplingRounds; ++round) round_done(0, 0);
  } else {
    data = generate_dataset(assets, s.data, round_done, shard);
    save_dataset(dataset_cache_path(out, shard), key, data);
  }
  report.data_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto rates = gather_each(comm, RankProgress{double(data.samples.size()) / std::max(1, s.data.outgoing_per_point), 0,
                                              cached ? 0.0 : report.data_seconds});
  for (const RankProgress& p : rates) report.sampling_rates.push_back(p.seconds > 0 ? p.done / p.seconds : 0.0);
  return data;
}

// Stage 2: the model to train, from the checkpoint when resuming and every
// rank read the same one; otherwise from scratch on every rank.
void start_model(const engine::scene::SceneAssets& assets, const fs::path& out, const BakeSettings& s, Communicator& comm,
                 model::TransferModel& m, Trainer::State& state, bool& resumed) {
  m = make_untrained_model(assets, s.latent_dim, s.layout, s.train.seed);
  resumed = s.resume && load_checkpoint(out, assets, m, state);
  const auto seen = gather_each(comm, resumed ? weights_hash(m) ^ static_cast<std::uint64_t>(state.iteration) : 0);
  if (resumed && !all_equal(seen)) {
    resumed = false;  // a rank could not read it, or read another one: start over together
    state = {};
    m = make_untrained_model(assets, s.latent_dim, s.layout, s.train.seed);
  }
}

// Removes <out>.dataset.R-of-N for every R and N (not <out>.dataset itself,
// which is removed by its one rank).
void remove_other_dataset_caches(const fs::path& out) {
  const std::string prefix = out.filename().string() + ".dataset.";
  std::error_code ec;
  const fs::path folder = out.has_parent_path() ? out.parent_path() : fs::path(".");
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(prefix, 0) == 0 && name.find("-of-") != std::string::npos) fs::remove(it->path(), ec);
  }
}

void write_model_metadata(model::TransferModel& m, const BakeSettings& s, const BakeReport& report) {
  const auto& l = m.decoder.layout();
  const auto bands = [](const BandErrors& e) { return nlohmann::json(std::vector<double>(e.rmse.begin(), e.rmse.end())); };
  m.visibility_fraction = s.data.visibility_fraction;
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
                                  {"ranks", report.ranks},
                                  {"rollbacks", report.rollbacks},
                                  {"validation_rmse", report.validation.total},
                                  {"validation_rmse_per_band", bands(report.validation)},
                                  {"constant_rmse_per_band", bands(report.constant)}}
                       .dump();
}

}  // namespace

std::optional<int> checkpoint_iteration(const fs::path& out, const engine::scene::SceneAssets& assets) {
  const auto read = read_checkpoint(out, assets);
  if (!read) return std::nullopt;
  return read->first.iteration;
}

BakeReport run_bake(const engine::scene::SceneAssets& assets, const fs::path& out, const BakeSettings& s,
                    const BakeCallbacks& cb, Communicator& comm) {
  BakeReport report;
  report.ranks = comm.size();
  const bool lead = comm.rank() == 0;
  const TransferDataset data = shard_dataset(assets, out, s, cb, comm, report);
  if (report.dataset_from_cache) report.data_seconds = data.seconds;
  std::uint64_t counts[3] = {data.samples.size(), data.training_count, data.validation_count()};
  {
    double sums[3] = {double(counts[0]), double(counts[1]), double(counts[2])};
    comm.sum(sums);
    for (int i = 0; i < 3; ++i) counts[i] = static_cast<std::uint64_t>(sums[i]);
  }
  report.samples = counts[0];
  report.training_samples = counts[1];
  report.validation_samples = counts[2];

  model::TransferModel m;
  Trainer::State state;
  bool resumed = false;
  start_model(assets, out, s, comm, m, state, resumed);
  Trainer trainer(data, assets, m, s.train, comm);
  if (resumed) {
    trainer.restore(state);
    report.resumed_from = state.iteration;
  }
  report.constant = trainer.constant_predictor();

  // Stage 3: training, rank 0 checkpointing.
  const auto t1 = std::chrono::steady_clock::now();
  const std::uint64_t sent_before = comm.bytes_sent();
  double loss_sum = 0;
  int loss_n = 0;
  std::vector<double> rates;
  Trainer::Times last_times;
  int last_exchange_at = 0;
  while (trainer.iteration() < s.train.iterations) {
    const float loss = trainer.step();
    loss_sum += loss;
    ++loss_n;
    const int it = trainer.iteration();
    if (comm.size() > 1 && it % 100 == 0 && it != last_exchange_at) {
      // Each rank's samples per second of its own compute, as rank 0 shows them.
      last_exchange_at = it;
      const Trainer::Times& t = trainer.times();
      const double busy = t.compute_seconds - last_times.compute_seconds;
      const auto all = gather_each(comm, busy > 0 ? double(t.samples - last_times.samples) / busy : 0.0);
      rates.assign(all.begin(), all.end());
      last_times = t;
    }
    if (lead && cb.training) cb.training(it, s.train.iterations, loss, rates);
    if (it % 100 == 0 && loss_n > 0) {
      report.loss_curve.emplace_back(it, static_cast<float>(loss_sum / loss_n));
      loss_sum = 0;
      loss_n = 0;
    }
    if (it % 1000 == 0) report.validation_curve.emplace_back(it, trainer.validate().total);
    if (lead && s.checkpoint_every > 0 && it % s.checkpoint_every == 0 && it < s.train.iterations)
      save_checkpoint(out, m, trainer.state());
  }
  report.train_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  report.iterations = trainer.iteration();
  report.rollbacks = trainer.rollbacks();
  report.compute_seconds = trainer.times().compute_seconds;
  report.exchange_seconds = trainer.times().exchange_seconds;
  const int steps = report.iterations - report.resumed_from;
  report.bytes_sent_per_step = steps > 0 ? double(comm.bytes_sent() - sent_before) / steps : 0.0;
  report.training_rates = rates;
  report.validation = trainer.validate();
  report.decoder_bytes = m.decoder_bytes();
  report.latent_bytes = m.latent_bytes();
  for (const auto& mesh : m.meshes) report.latent_rows += mesh.latents.rows();
  if (!all_equal(gather_each(comm, weights_hash(m))))
    throw std::runtime_error("bake: the ranks' copies of the model differ after training (the transport's sums "
                             "were not the same on every rank); no model was written");

  // Stage 4: rank 0 writes the model; each rank cleans up after itself, and
  // rank 0 after bakes on other rank counts too (a bake resumed on another
  // N traced its own shards): with the model written, no cache is needed.
  std::error_code ec;
  if (lead) {
    write_model_metadata(m, s, report);
    model::save_model(out, m);
    fs::remove(checkpoint_path(out), ec);
    fs::remove(checkpoint_path(out).string() + ".state", ec);  // the two-file checkpoint of earlier builds
    if (!s.keep_dataset) remove_other_dataset_caches(out);
  }
  if (!s.keep_dataset) fs::remove(dataset_cache_path(out, {comm.rank(), comm.size()}), ec);
  return report;
}

}  // namespace transgi::bake
