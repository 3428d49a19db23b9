#include "bake/trainer.h"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cmath>
#include <stdexcept>
#include <string>

#include "engine/jobs/parallel_for.h"

namespace transgi::bake {

using model::kTransferInputExtra;

namespace {
constexpr float kBeta1 = 0.9f, kBeta2 = 0.999f, kEps = 1e-8f;
constexpr int kSnapshotEvery = 100;

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

int band_of(int k) { return k < 1 ? 0 : k < 4 ? 1 : k < 9 ? 2 : k < 16 ? 3 : 4; }

// Squared errors summed per SH band (over RGB) and overall.
struct BandAccumulator {
  std::array<double, 5> sums{};
  std::array<std::size_t, 5> counts{};
  double total = 0;
  std::size_t values = 0;
  void add(const float* predicted, const float* target) {
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 25; ++k) {
        const double diff = static_cast<double>(predicted[c * 25 + k]) - target[c * 25 + k];
        sums[static_cast<std::size_t>(band_of(k))] += diff * diff;
        ++counts[static_cast<std::size_t>(band_of(k))];
        total += diff * diff;
        ++values;
      }
  }
  // The sums of every rank's accumulator, on every rank.
  void sum_over(Communicator& comm) {
    std::array<double, 12> all{};
    for (std::size_t b = 0; b < 5; ++b) all[b] = sums[b], all[5 + b] = static_cast<double>(counts[b]);
    all[10] = total;
    all[11] = static_cast<double>(values);
    comm.sum(all);
    for (std::size_t b = 0; b < 5; ++b) sums[b] = all[b], counts[b] = static_cast<std::size_t>(all[5 + b]);
    total = all[10];
    values = static_cast<std::size_t>(all[11]);
  }
  [[nodiscard]] BandErrors result() const {
    BandErrors e;
    for (std::size_t b = 0; b < 5; ++b) e.rmse[b] = counts[b] ? std::sqrt(sums[b] / static_cast<double>(counts[b])) : 0.0;
    e.total = values ? std::sqrt(total / static_cast<double>(values)) : 0.0;
    return e;
  }
};
}  // namespace

model::TransferModel make_untrained_model(const engine::scene::SceneAssets& assets, int latent_dim,
                                          model::MlpLayout layout, std::uint64_t seed) {
  layout.inputs = latent_dim + kTransferInputExtra;
  layout.outputs = kTransferValues;
  model::TransferModel m;
  m.latent_dim = latent_dim;
  m.decoder = model::Mlp(layout);
  m.decoder.initialise(seed);
  engine::math::Pcg32 rng(seed, 0x1a7e);
  for (std::uint32_t i = 0; i < assets.meshes.size(); ++i) {
    model::MeshLatents ml;
    ml.name = assets.meshes[i]->name;
    ml.content_hash = model::mesh_content_hash(assets, i);
    ml.latents = model::make_latent_table(*assets.meshes[i], latent_dim);
    for (float& v : ml.latents.values) v = 0.1f * (2.0f * rng.next_float() - 1.0f);
    m.meshes.push_back(std::move(ml));
  }
  return m;
}

Trainer::Trainer(const TransferDataset& data, const engine::scene::SceneAssets& assets, model::TransferModel& model,
                 TrainSettings settings, Communicator& comm)
    : data_(data), assets_(assets), model_(model), settings_(std::move(settings)), comm_(comm), rng_(settings_.seed, 0x7a41) {
  if (data.all_training_samples == 0) throw std::invalid_argument("the dataset has no training samples");
  if (data.shard.count != comm.size() || data.shard.rank != comm.rank())
    throw std::invalid_argument("the dataset is rank " + std::to_string(data.shard.rank) + " of " + std::to_string(data.shard.count) +
                                "'s shard, but this trainer is rank " + std::to_string(comm.rank()) + " of " +
                                std::to_string(comm.size()));
  if (model.meshes.size() != assets.meshes.size()) throw std::invalid_argument("model and scene have different mesh counts");
  // The model predicts what its targets are: transfer over albedo or not.
  model_.demodulated = data.demodulated;
  for (const auto& m : model_.meshes) {
    latent_offset_.push_back(latent_count_);
    latent_count_ += m.latents.values.size();
  }
  const int blocks = settings_.gradient_blocks;
  if (blocks < 1 || blocks > 4096 || !power_of_two(blocks))
    throw std::invalid_argument("gradient_blocks must be a power of two from 1 to 4096, not " + std::to_string(blocks));
  if (data.training_point_hashes.size() * static_cast<std::size_t>(data.outgoing) != data.training_count)
    throw std::invalid_argument("the dataset's training points have no hashes (a dataset from before gradient blocks)");
  for (std::uint32_t h : data.training_point_hashes) block_of_point_.push_back(static_cast<std::uint16_t>(h % static_cast<std::uint32_t>(blocks)));
  block_samples_.resize(static_cast<std::size_t>(blocks));
  blocks_.resize(static_cast<std::size_t>(blocks));
  m_.assign(parameter_count(), 0.0f);
  v_.assign(parameter_count(), 0.0f);
  grad_.assign(parameter_count(), 0.0f);
  snapshot();
}

std::size_t Trainer::parameter_count() const { return model_.decoder.params().size() + latent_count_; }

float* Trainer::latent_ptr(std::size_t flat) {
  const auto it = std::upper_bound(latent_offset_.begin(), latent_offset_.end(), flat) - 1;
  const std::size_t mesh = static_cast<std::size_t>(it - latent_offset_.begin());
  return model_.meshes[mesh].latents.values.data() + (flat - *it);
}

float Trainer::current_learning_rate() const {
  float lr = settings_.learning_rate * lr_scale_;
  for (float f : settings_.milestones)
    if (iteration_ >= static_cast<int>(f * static_cast<float>(settings_.iterations))) lr *= settings_.decay;
  return lr;
}

void Trainer::predict(std::span<const std::size_t> idx, std::vector<float>& x, std::vector<float>& y,
                      model::MlpWorkspace& ws) const {
  const int in = model_.decoder.layout().inputs, d = model_.latent_dim;
  x.resize(idx.size() * static_cast<std::size_t>(in));
  y.resize(idx.size() * kTransferValues);
  std::vector<float> z(static_cast<std::size_t>(d));
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const TransferSample& s = data_.samples[idx[i]];
    model_.meshes[s.mesh].latents.interpolate(*assets_.meshes[s.mesh], s.triangle, s.barycentric, z.data());
    model::assemble_input(z.data(), d, s.albedo, s.normal, s.wo, x.data() + i * static_cast<std::size_t>(in));
  }
  model_.decoder.forward(x.data(), static_cast<int>(idx.size()), y.data(), ws, settings_.backend);
}

void Trainer::Gradients::clear() {
  empty = true;
  loss = 0;
  rows.clear();
  row_values.clear();
}

void Trainer::Gradients::zero(std::size_t decoder_size) {
  clear();
  empty = false;
  decoder.assign(decoder_size, 0.0f);
}

void Trainer::draw_local_blocks() {
  for (auto& b : block_samples_) b.clear();
  const auto k = static_cast<std::uint64_t>(data_.outgoing);
  for (int i = 0; i < settings_.batch; ++i) {
    const std::uint64_t global = rng_.next_u32() % data_.all_training_samples;
    const std::int64_t mine = comm_.size() == 1 ? static_cast<std::int64_t>(global) : data_.local_training_sample(global);
    if (mine < 0) continue;
    const auto local = static_cast<std::uint64_t>(mine);
    block_samples_[block_of_point_[local / k]].push_back(static_cast<std::size_t>(local));
  }
}

// Each block this rank holds samples of, alone: its own forward and
// backward pass, its parameter gradients and latent rows. Not one pass over
// all of them: oneDNN's AVX2 products give a row other bits when the other
// rows change (a 2-rank bake then left the one process's steps), while a
// block's products are the same on any rank count. Each block's products
// run on one thread, the blocks in parallel: oneDNN's AVX2 sgemm also
// splits a product's rows by its thread count, so a block multiplied on
// two threads rounds otherwise than on one, and the bake's bits followed
// --threads.
void Trainer::compute_blocks() {
  block_ws_.resize(blocks_.size());
  engine::jobs::parallel_for<std::size_t>(0, blocks_.size(), 1, [&](std::size_t b0, std::size_t b1) {
    const model::GemmThreadsScope one_thread(1);
    for (std::size_t b = b0; b < b1; ++b) {
      blocks_[b].clear();
      if (!block_samples_[b].empty()) compute_block(block_samples_[b], blocks_[b], block_ws_[b]);
    }
  });
  for (const auto& samples : block_samples_) times_.samples += samples.size();
}

void Trainer::compute_block(std::span<const std::size_t> idx, Gradients& out, model::MlpWorkspace& ws) const {
  const std::size_t n_dec = model_.decoder.params().size();
  out.zero(n_dec);
  std::vector<float> x, y;
  predict(idx, x, y, ws);

  // L1 loss and its gradient, scaled by the whole batch of every rank.
  const float scale = 1.0f / static_cast<float>(static_cast<std::size_t>(settings_.batch) * kTransferValues);
  std::vector<float> dy(y.size());
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const float* t = data_.target(idx[i]);
    for (int k = 0; k < kTransferValues; ++k) {
      const float diff = y[i * kTransferValues + static_cast<std::size_t>(k)] - t[k];
      out.loss += std::abs(diff);
      dy[i * kTransferValues + static_cast<std::size_t>(k)] = diff > 0 ? scale : diff < 0 ? -scale : 0.0f;
    }
  }
  const int in = model_.decoder.layout().inputs;
  std::vector<float> dx(x.size());
  model_.decoder.backward(x.data(), static_cast<int>(idx.size()), dy.data(), ws, out.decoder, dx.data(), settings_.backend);

  // The block's latent rows, summed in its samples' order.
  const auto d = static_cast<std::size_t>(model_.latent_dim);
  if (d == 0) return;
  out.rows = latent_rows_of(idx);
  out.row_values.assign(out.rows.size() * d, 0.0f);
  for (std::size_t i = 0; i < idx.size(); ++i) {
    const TransferSample& s = data_.samples[idx[i]];
    model_.meshes[s.mesh].latents.scatter_gradient_rows(*assets_.meshes[s.mesh], s.triangle, s.barycentric,
                                                        dx.data() + i * static_cast<std::size_t>(in), latent_offset_[s.mesh] / d, out.rows,
                                                        out.row_values);
  }
}

void Trainer::add_rows(Gradients& into, const Gradients& from) const {
  if (from.rows.empty()) return;
  const auto d = static_cast<std::size_t>(model_.latent_dim);
  Gradients merged;
  merged.rows.reserve(into.rows.size() + from.rows.size());
  merged.row_values.reserve((into.rows.size() + from.rows.size()) * d);
  std::size_t a = 0, b = 0;
  while (a < into.rows.size() || b < from.rows.size()) {
    const bool take_a = b == from.rows.size() || (a < into.rows.size() && into.rows[a] <= from.rows[b]);
    const bool take_b = a == into.rows.size() || (b < from.rows.size() && from.rows[b] <= into.rows[a]);
    merged.rows.push_back(take_a ? into.rows[a] : from.rows[b]);
    for (std::size_t k = 0; k < d; ++k) {
      const float va = take_a ? into.row_values[a * d + k] : 0.0f;
      const float vb = take_b ? from.row_values[b * d + k] : 0.0f;
      merged.row_values.push_back(take_a && take_b ? va + vb : take_a ? va : vb);
    }
    a += take_a;
    b += take_b;
  }
  into.rows = std::move(merged.rows);
  into.row_values = std::move(merged.row_values);
}

void Trainer::add(Gradients& into, Gradients& from) const {
  if (from.empty) return;
  if (into.empty) {  // `from` is not read again: its buffers are taken, not copied
    std::swap(into, from);
    return;
  }
  into.loss += from.loss;
  for (std::size_t i = 0; i < into.decoder.size(); ++i) into.decoder[i] += from.decoder[i];
  add_rows(into, from);
}

// The tree: block v takes block v + d for d = blocks / 2, blocks / 4, ..., 1.
// With N ranks (a power of two, at most the block count) block v is rank
// v mod N's, so every level with d >= N sums one rank's blocks, and the
// levels below it pair rank r with rank r + d: what Communicator::sum does.
Trainer::Gradients& Trainer::sum_own_blocks() {
  const int n = comm_.size(), rank = comm_.rank(), blocks = settings_.gradient_blocks;
  const bool aligned = power_of_two(n) && n <= blocks;
  for_each_tree_pair(blocks, aligned ? n : 1, [&](int v, int w) {
    if (!aligned || v % n == rank) add(blocks_[static_cast<std::size_t>(v)], blocks_[static_cast<std::size_t>(w)]);
  });
  return blocks_[static_cast<std::size_t>(aligned ? rank : 0)];
}

float Trainer::step() {
  const auto t0 = std::chrono::steady_clock::now();
  clear_latent_gradients();
  draw_local_blocks();
  compute_blocks();
  Gradients& sum = sum_own_blocks();
  if (sum.empty) sum.zero(model_.decoder.params().size());  // none of the batch is this rank's
  const auto t1 = std::chrono::steady_clock::now();
  if (comm_.size() > 1) exchange_gradients(sum);
  const auto t2 = std::chrono::steady_clock::now();
  take_gradients(sum);
  const double loss = sum.loss / (static_cast<double>(settings_.batch) * kTransferValues);

  if (!gradients_finite(loss)) rollback();
  else adam_step();
  const auto t3 = std::chrono::steady_clock::now();
  times_.compute_seconds += std::chrono::duration<double>((t1 - t0) + (t3 - t2)).count();
  times_.exchange_seconds += std::chrono::duration<double>(t2 - t1).count();
  return static_cast<float>(loss);
}

void Trainer::clear_latent_gradients() {
  const std::size_t n_dec = model_.decoder.params().size();
  const auto d = static_cast<std::size_t>(model_.latent_dim);
  for (std::uint64_t r : touched_rows_) std::fill_n(grad_.begin() + static_cast<std::ptrdiff_t>(n_dec + r * d), d, 0.0f);
  touched_rows_.clear();
}

void Trainer::take_gradients(const Gradients& sum) {
  const std::size_t n_dec = model_.decoder.params().size();
  const auto d = static_cast<std::size_t>(model_.latent_dim);
  std::copy(sum.decoder.begin(), sum.decoder.end(), grad_.begin());
  touched_rows_ = sum.rows;
  for (std::size_t r = 0; r < touched_rows_.size(); ++r)
    std::copy_n(sum.row_values.data() + r * d, d, grad_.data() + n_dec + touched_rows_[r] * d);
}

std::vector<std::uint64_t> Trainer::latent_rows_of(std::span<const std::size_t> batch) const {
  const auto d = static_cast<std::size_t>(model_.latent_dim);
  std::vector<std::uint64_t> rows;
  if (d == 0) return rows;
  for (std::size_t i : batch) {
    const TransferSample& s = data_.samples[i];
    const auto& table = model_.meshes[s.mesh].latents;
    const glm::uvec3 t = assets_.meshes[s.mesh]->triangles[s.triangle];
    for (std::uint32_t v : {t.x, t.y, t.z}) rows.push_back(latent_offset_[s.mesh] / d + table.vertex_to_latent[v]);
  }
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  return rows;
}

bool Trainer::gradients_finite(double loss) const {
  if (!std::isfinite(loss)) return false;
  if (settings_.latent_updates == LatentUpdates::All) {
    for (float g : grad_)
      if (!std::isfinite(g)) return false;
    return true;
  }
  const std::size_t n_dec = model_.decoder.params().size(), d = static_cast<std::size_t>(model_.latent_dim);
  for (std::size_t i = 0; i < n_dec; ++i)
    if (!std::isfinite(grad_[i])) return false;
  for (std::uint64_t r : touched_rows_)
    for (std::size_t k = 0; k < d; ++k)
      if (!std::isfinite(grad_[n_dec + r * d + k])) return false;
  return true;
}

// The decoder's gradients and the loss are summed densely. A latent row gets
// gradients only from the samples on its triangles, at most 3 x batch rows a
// step however large the level, so the ranks exchange only the rows they
// touched (a row index and its values): for a 10 M-vertex level that is
// about 200 KB a step where the dense table would be 280 MB (docs/bake.md).
// The rows are summed in the same tree as the dense sums.
void Trainer::exchange_gradients(Gradients& mine) {
  comm_.sum(std::span(mine.decoder));
  comm_.sum(std::span(&mine.loss, 1));
  const auto d = static_cast<std::size_t>(model_.latent_dim);
  if (d == 0) return;

  const std::size_t row_bytes = sizeof(std::uint64_t) + d * sizeof(float);
  std::vector<std::byte> packed(mine.rows.size() * row_bytes);
  for (std::size_t r = 0; r < mine.rows.size(); ++r) {
    std::memcpy(packed.data() + r * row_bytes, &mine.rows[r], sizeof(std::uint64_t));
    std::memcpy(packed.data() + r * row_bytes + sizeof(std::uint64_t), mine.row_values.data() + r * d, d * sizeof(float));
  }
  const auto all = comm_.all_gather(packed);
  std::vector<Gradients> parts(all.size());
  for (std::size_t p = 0; p < all.size(); ++p) {
    if (all[p].size() % row_bytes != 0) throw std::runtime_error("bake: a rank sent a torn latent row");
    const std::size_t count = all[p].size() / row_bytes;
    parts[p].rows.resize(count);
    parts[p].row_values.resize(count * d);
    for (std::size_t r = 0; r < count; ++r) {
      std::uint64_t row = 0;
      std::memcpy(&row, all[p].data() + r * row_bytes, sizeof(row));
      if (row * d + d > latent_count_ || (r > 0 && row <= parts[p].rows[r - 1]))
        throw std::runtime_error("bake: a rank sent a latent row outside the model or out of order");
      parts[p].rows[r] = row;
      std::memcpy(parts[p].row_values.data() + r * d, all[p].data() + r * row_bytes + sizeof(row), d * sizeof(float));
    }
  }
  const int n = comm_.size();
  if (power_of_two(n)) {
    for_each_tree_pair(n, 1, [&](int into, int from) {
      add_rows(parts[static_cast<std::size_t>(into)], parts[static_cast<std::size_t>(from)]);
    });
  } else {
    for (int r = 1; r < n; ++r) add_rows(parts[0], parts[static_cast<std::size_t>(r)]);
  }
  mine.rows = std::move(parts[0].rows);
  mine.row_values = std::move(parts[0].row_values);
}

// Adam with bias correction; the latents get their own rate.
void Trainer::adam_step() {
  const std::size_t n_dec = model_.decoder.params().size();
  ++iteration_;
  const float lr = current_learning_rate();
  const float lr_latent = settings_.latent_learning_rate * (lr / settings_.learning_rate);
  const float c1 = 1.0f - std::pow(kBeta1, static_cast<float>(iteration_));
  const float c2 = 1.0f - std::pow(kBeta2, static_cast<float>(iteration_));
  auto update = [&](std::size_t i, float& p, float rate) {
    const float g = grad_[i];
    m_[i] = kBeta1 * m_[i] + (1 - kBeta1) * g;
    v_[i] = kBeta2 * v_[i] + (1 - kBeta2) * g * g;
    p -= rate * (m_[i] / c1) / (std::sqrt(v_[i] / c2) + kEps);
  };
  auto& params = model_.decoder.params();
  for (std::size_t i = 0; i < n_dec; ++i) update(i, params[i], lr);
  if (settings_.latent_updates == LatentUpdates::Touched) {
    const auto d = static_cast<std::size_t>(model_.latent_dim);
    for (std::uint64_t r : touched_rows_) {
      float* row = latent_ptr(r * d);  // a row never spans two meshes
      for (std::size_t k = 0; k < d; ++k) update(n_dec + r * d + k, row[k], lr_latent);
    }
  } else {
    std::size_t flat = 0;
    for (auto& mesh : model_.meshes)
      for (float& p : mesh.latents.values) update(n_dec + flat++, p, lr_latent);
  }
  if (iteration_ % kSnapshotEvery == 0) snapshot();
}

void Trainer::snapshot() {
  good_params_ = model_.decoder.params();
  good_latents_.clear();
  for (const auto& m : model_.meshes) good_latents_.insert(good_latents_.end(), m.latents.values.begin(), m.latents.values.end());
  good_m_ = m_;
  good_v_ = v_;
  good_iteration_ = iteration_;
}

void Trainer::rollback() {
  model_.decoder.params() = good_params_;
  std::size_t at = 0;
  for (auto& m : model_.meshes) {
    std::copy_n(good_latents_.begin() + static_cast<std::ptrdiff_t>(at), m.latents.values.size(), m.latents.values.begin());
    at += m.latents.values.size();
  }
  m_ = good_m_;
  v_ = good_v_;
  iteration_ = good_iteration_;
  lr_scale_ *= 0.5f;
  ++rollbacks_;
}

BandErrors Trainer::validate() const {
  BandAccumulator acc;
  const std::size_t n = data_.validation_count();
  model::MlpWorkspace ws;
  std::vector<float> x, y;
  std::vector<std::size_t> idx;
  for (std::size_t start = 0; start < n; start += 4096) {
    idx.clear();
    for (std::size_t i = start; i < std::min(n, start + 4096); ++i) idx.push_back(data_.training_count + i);
    predict(idx, x, y, ws);
    for (std::size_t i = 0; i < idx.size(); ++i) acc.add(y.data() + i * kTransferValues, data_.target(idx[i]));
  }
  acc.sum_over(comm_);
  return acc.result();
}

BandErrors Trainer::constant_predictor() const {
  std::array<double, kTransferValues + 1> sum{};  // the targets' sums, then their count
  for (std::size_t i = 0; i < data_.training_count; ++i)
    for (int k = 0; k < kTransferValues; ++k) sum[static_cast<std::size_t>(k)] += data_.target(i)[k];
  sum[kTransferValues] = static_cast<double>(data_.training_count);
  comm_.sum(sum);
  std::array<float, kTransferValues> prediction{};
  for (std::size_t k = 0; k < prediction.size(); ++k) prediction[k] = static_cast<float>(sum[k] / sum[kTransferValues]);
  BandAccumulator acc;
  for (std::size_t i = 0; i < data_.validation_count(); ++i) acc.add(prediction.data(), data_.target(data_.training_count + i));
  acc.sum_over(comm_);
  return acc.result();
}

Trainer::State Trainer::state() const { return {iteration_, lr_scale_, rollbacks_, m_, v_}; }

void Trainer::restore(const State& s) {
  if (s.m.size() != m_.size() || s.v.size() != v_.size()) throw std::invalid_argument("checkpoint does not match this model");
  iteration_ = s.iteration;
  lr_scale_ = s.lr_scale;
  rollbacks_ = s.rollbacks;
  m_ = s.m;
  v_ = s.v;
  snapshot();
}

}  // namespace transgi::bake
