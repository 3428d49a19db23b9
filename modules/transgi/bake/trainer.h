#pragma once
// Joint training of the decoder and the per-vertex latents (paper Section
// 4.2): Adam, L1 loss, multi-step learning-rate decay, batches of 2048.
// Every step checks the loss and gradients for finiteness; on a non-finite
// value it rolls back to the last good state and halves the learning rate,
// and counts it, so a run never silently produces NaN weights.
#include <array>
#include <cstdint>
#include <vector>

#include "bake/communicator.h"
#include "bake/dataset.h"
#include "model/transfer_model.h"

namespace transgi::bake {

// Which latent rows a step's Adam update moves.
enum class LatentUpdates {
  // Every row, every step: the moments of rows without gradients decay and
  // keep moving them. What every model so far was trained with.
  All,
  // Only the rows the step's batch touched, on every rank alike (lazy Adam,
  // as embedding tables are trained): a step's cost follows the batch, not
  // the level (docs/bake.md, "Scaling"), at the cost of other optimiser steps.
  Touched,
};

struct TrainSettings {
  int iterations = 20000;  // higher = lower error, at the cost of time (the paper trains 200k on a GPU)
  int batch = 2048;
  // The paper uses 1e-4 over 200k iterations; with ~30x fewer steps on a CPU
  // a larger rate converges further in the same time (docs/bake.md).
  float learning_rate = 2e-3f;
  float latent_learning_rate = 1e-2f;    // latents see few gradients per step each
  std::vector<float> milestones = {0.5f, 0.75f, 0.9f};  // fractions of `iterations`
  float decay = 0.33f;                   // learning-rate factor at each milestone
  std::uint64_t seed = 7;
  LatentUpdates latent_updates = LatentUpdates::All;
  // A batch's gradients are summed as a fixed binary tree over this many
  // blocks of its samples (a sample's block: its point's point_hash mod the
  // count), so that a bake on any power-of-two number of ranks up to this
  // count takes the one process's steps bit for bit (docs/bake.md). The
  // blocks are also what a rank's threads share (each block's products on
  // one thread, so the bits do not depend on the thread count either): fewer
  // blocks than threads leave cores idle. Higher = the same bits on more
  // ranks, at the cost of smaller matrix products. A power of two from 1 to
  // 4096.
  int gradient_blocks = 8;
  model::GemmBackend backend = model::default_gemm_backend();
};

struct BandErrors {
  std::array<double, 5> rmse{};  // per SH band l = 0..4, over RGB and the band's 2l+1 coefficients
  double total = 0;              // over all 75 values
};

// Data-parallel over the ranks of `comm` (docs/bake.md, "Baking on many
// machines"): every rank holds the whole model and draws the same batches
// from all ranks' samples; each computes the gradients of the samples its
// shard holds, block by block (TrainSettings::gradient_blocks); the blocks'
// gradients are summed in a fixed tree, the decoder's densely and the
// latents' as sparse rows (only the rows the batch touched), first the
// rank's own blocks, then over the ranks, so every rank takes the same
// optimiser step. On a power-of-two number of ranks up to the block count
// the tree is the one process's, and so are the steps, bit for bit.
class Trainer {
 public:
  // The model must already hold a decoder of the right input size and
  // latent tables for every mesh (make_untrained_model()).
  Trainer(const TransferDataset& data, const engine::scene::SceneAssets& assets, model::TransferModel& model,
          TrainSettings settings, Communicator& comm = solo());

  // One optimisation step; returns the batch's mean L1 loss.
  float step();
  [[nodiscard]] BandErrors validate() const;
  // The same errors for a predictor that always outputs the training mean.
  [[nodiscard]] BandErrors constant_predictor() const;

  [[nodiscard]] int iteration() const { return iteration_; }
  [[nodiscard]] int rollbacks() const { return rollbacks_; }
  [[nodiscard]] float current_learning_rate() const;

  // Where this rank's time went since construction, and what it computed.
  struct Times {
    double compute_seconds = 0;   // forward, backward, optimiser step
    double exchange_seconds = 0;  // summing over the ranks (waiting for the slowest included)
    std::uint64_t samples = 0;    // samples of the batches this rank computed
  };
  [[nodiscard]] const Times& times() const { return times_; }

  // Checkpoint state (optimizer moments included) for --resume.
  struct State {
    int iteration = 0;
    float lr_scale = 1.0f;
    int rollbacks = 0;
    std::vector<float> m, v;  // Adam moments over [decoder params, all latents]
  };
  [[nodiscard]] State state() const;
  void restore(const State& s);

 private:
  void predict(std::span<const std::size_t> indices, std::vector<float>& inputs, std::vector<float>& outputs,
               model::MlpWorkspace& ws) const;
  float* latent_ptr(std::size_t flat);
  std::size_t parameter_count() const;

  // One block's (or a subtree's) share of a step: its samples' summed L1
  // loss, the decoder's gradients and the latent rows its samples touched
  // (ascending) with their gradients, latent_dim floats a row.
  // A block no sample of this rank fell in stays `empty`, its decoder
  // gradients unallocated: it adds nothing to the tree (adding zero changes
  // no sum), so a rank pays only for its own blocks whatever the count.
  struct Gradients {
    bool empty = true;
    double loss = 0;
    std::vector<float> decoder;
    std::vector<std::uint64_t> rows;
    std::vector<float> row_values;
    void clear();
    void zero(std::size_t decoder_size);  // not empty, every value 0
  };
  // The step's stages, in order.
  // grad_'s latent part back to zero (only last step's rows held values).
  void clear_latent_gradients();
  // This rank's share of a batch drawn over every rank's training samples,
  // sorted into blocks (each in draw order).
  void draw_local_blocks();
  void compute_blocks();
  void compute_block(std::span<const std::size_t> idx, Gradients& out, model::MlpWorkspace& ws) const;
  // The rank's blocks summed in the tree's order, up to the level where the
  // ranks' partial sums meet; returns the rank's partial sum.
  Gradients& sum_own_blocks();
  // The ranks' partial sums summed over the ranks, in the tree's order.
  void exchange_gradients(Gradients& mine);
  // grad_ and touched_rows_ from the step's sum.
  void take_gradients(const Gradients& sum);

  void add_rows(Gradients& into, const Gradients& from) const;
  // into += from; `from` may be left with into's old buffers.
  void add(Gradients& into, Gradients& from) const;
  // The flat latent rows (over every mesh) that these samples interpolate, sorted, once each.
  std::vector<std::uint64_t> latent_rows_of(std::span<const std::size_t> batch) const;
  [[nodiscard]] bool gradients_finite(double loss) const;
  void adam_step();
  void snapshot();
  void rollback();

  const TransferDataset& data_;
  const engine::scene::SceneAssets& assets_;
  model::TransferModel& model_;
  TrainSettings settings_;
  Communicator& comm_;
  Times times_;
  std::vector<std::size_t> latent_offset_;  // per mesh, into the flat latent index space
  std::size_t latent_count_ = 0;
  std::vector<float> m_, v_, grad_;
  // The latent rows the last step's batch touched on every rank: the only
  // rows of grad_'s latent part that are not zero.
  std::vector<std::uint64_t> touched_rows_;
  std::vector<std::uint16_t> block_of_point_;           // per local training point
  std::vector<std::vector<std::size_t>> block_samples_;  // this step's, per block
  std::vector<Gradients> blocks_;
  int iteration_ = 0;
  float lr_scale_ = 1.0f;
  int rollbacks_ = 0;
  engine::math::Pcg32 rng_;
  model::MlpWorkspace ws_;
  std::vector<model::MlpWorkspace> block_ws_;  // per gradient block (compute_blocks runs them in parallel)
  // Last good state, for rollback.
  std::vector<float> good_params_, good_latents_, good_m_, good_v_;
  int good_iteration_ = 0;
};

// A decoder with `layout` (inputs = latent_dim + 9) and zero-ish random latents for every mesh.
model::TransferModel make_untrained_model(const engine::scene::SceneAssets& assets, int latent_dim,
                                          model::MlpLayout layout, std::uint64_t seed);

}  // namespace transgi::bake
