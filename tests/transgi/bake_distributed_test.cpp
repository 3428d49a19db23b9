// The bake on several ranks (docs/bake.md, "Baking on many machines"), with
// the ranks played by threads (bake/thread_communicator.h), so the sharding
// and the data-parallel training are tested whether or not the build has MPI.
// The MPI transport itself: mpi_bake_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <thread>

#include "bake/bake_job.h"
#include "bake/thread_communicator.h"
#include "bake/trainer.h"
#include "bake_fixtures.h"
#include "model/gemm.h"
#include "model/model_file.h"

using namespace bake_fixtures;

namespace {

bake::DatasetSettings small_data() {
  auto s = tiny_data();
  s.points = 600;
  s.rays = 64;
  return s;
}

// Runs fn(rank, communicator) on `ranks` threads at once.
template <class Fn>
void on_ranks(int ranks, Fn fn) {
  auto group = bake::make_thread_group(ranks);
  std::vector<std::thread> threads;
  for (int r = 0; r < ranks; ++r) threads.emplace_back([&, r] { fn(r, *group[static_cast<std::size_t>(r)]); });
  for (auto& t : threads) t.join();
}

std::vector<float> weights(const model::TransferModel& m) {
  std::vector<float> w = m.decoder.params();
  for (const auto& mesh : m.meshes) w.insert(w.end(), mesh.latents.values.begin(), mesh.latents.values.end());
  return w;
}

// |a - b| / |a| over every weight.
double relative_distance(const std::vector<float>& a, const std::vector<float>& b) {
  double diff = 0, norm = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff += double(a[i] - b[i]) * (a[i] - b[i]), norm += double(a[i]) * a[i];
  return std::sqrt(diff / norm);
}

// The one-process run the ranks are held to: `steps` steps from the model of seed 3.
struct SoloRun {
  model::TransferModel model;
  std::vector<float> losses;
  bake::BandErrors validation;
};
SoloRun train_alone(const engine::scene::SceneAssets& assets, const bake::TransferDataset& data, const bake::TrainSettings& ts,
                    const model::MlpLayout& layout, int steps) {
  SoloRun run{bake::make_untrained_model(assets, 7, layout, 3), {}, {}};
  bake::Trainer trainer(data, assets, run.model, ts);
  for (int i = 0; i < steps; ++i) run.losses.push_back(trainer.step());
  run.validation = trainer.validate();
  return run;
}

bool same_sample(const bake::TransferSample& a, const bake::TransferSample& b) {
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

}  // namespace

// Every point is traced by exactly one rank, with the rays it gets in the
// one-process bake: the shards together are that dataset, bit for bit, and
// each global training sample is found on exactly one shard.
TEST(BakeShards, TheRanksShardsTogetherAreTheOneProcessDataset) {
  const auto assets = tiny_scene();
  const auto s = small_data();
  const auto one = bake::generate_dataset(assets, s);
  ASSERT_EQ(one.all_training_samples, one.training_count);
  constexpr int kRanks = 3;
  std::vector<bake::TransferDataset> shards;
  for (int r = 0; r < kRanks; ++r) shards.push_back(bake::generate_dataset(assets, s, {}, {r, kRanks}));

  std::size_t samples = 0, training = 0;
  for (const auto& d : shards) {
    samples += d.samples.size();
    training += d.training_count;
    EXPECT_EQ(d.all_training_samples, one.training_count);
    EXPECT_TRUE(std::is_sorted(d.training_points.begin(), d.training_points.end()));
    // Balanced by the hash: 600 points, a third each, within 4 standard deviations.
    const double points = static_cast<double>(d.samples.size()) / s.outgoing_per_point;
    EXPECT_NEAR(points, 200.0, 4 * std::sqrt(600 * (1.0 / 3) * (2.0 / 3)));
  }
  EXPECT_EQ(samples, one.samples.size());
  EXPECT_EQ(training, one.training_count);

  for (std::uint64_t g = 0; g < one.training_count; ++g) {
    int holders = 0;
    for (const auto& d : shards) {
      const std::int64_t local = d.local_training_sample(g);
      if (local < 0) continue;
      ++holders;
      const auto i = static_cast<std::size_t>(local);
      ASSERT_TRUE(same_sample(d.samples[i], one.samples[g])) << "global sample " << g;
      ASSERT_EQ(std::memcmp(d.target(i), one.target(g), sizeof(float) * bake::kTransferValues), 0) << "global sample " << g;
    }
    ASSERT_EQ(holders, 1) << "global training sample " << g;
  }
  // The validation points too, each on one shard.
  std::multimap<float, std::size_t> validation;  // keyed by the first target value
  for (std::size_t i = one.training_count; i < one.samples.size(); ++i) validation.emplace(one.target(i)[0], i);
  std::size_t found = 0;
  for (const auto& d : shards)
    for (std::size_t i = d.training_count; i < d.samples.size(); ++i) {
      const auto [b, e] = validation.equal_range(d.target(i)[0]);
      for (auto it = b; it != e; ++it)
        if (same_sample(d.samples[i], one.samples[it->second])) {
          ++found;
          break;
        }
    }
  EXPECT_EQ(found, one.validation_count());
}

// Communicator::sum's contract on a power-of-two group: rank r + N/2 is added
// to rank r first, then pairs at N/4, ..., 1, whatever the transport. Values
// whose float sum depends on the order tell the tree from rank order: with
// 1e8, 1, -1e8, 1 the tree gives (1e8 - 1e8) + (1 + 1) = 2, rank order
// ((1e8 + 1) - 1e8) + 1 = 1 (1e8 + 1 rounds to 1e8).
TEST(DistributedTraining, AGroupsSumIsTheFixedTreeOverItsRanks) {
  const float mine[4] = {1e8f, 1.0f, -1e8f, 1.0f};
  std::vector<float> sums(4), double_sums(4);
  on_ranks(4, [&](int r, bake::Communicator& comm) {
    std::vector<float> v{mine[r]};
    comm.sum(std::span(v));
    sums[static_cast<std::size_t>(r)] = v[0];
    std::vector<double> d{r == 0 ? 1e17 : r == 2 ? -1e17 : 1.0};
    comm.sum(std::span(d));
    double_sums[static_cast<std::size_t>(r)] = static_cast<float>(d[0]);
  });
  for (int r = 0; r < 4; ++r) {
    EXPECT_EQ(sums[static_cast<std::size_t>(r)], 2.0f) << "rank " << r;
    EXPECT_EQ(double_sums[static_cast<std::size_t>(r)], 2.0f) << "rank " << r << ", in double";
  }
}

// Two and four ranks draw the batches the one process draws, and the
// gradients of each block of a batch are summed in the one process's tree:
// the same steps, the same bits, on every rank.
TEST(DistributedTraining, TwoAndFourRanksTakeTheOneProcessStepsBitForBit) {
  const auto assets = tiny_scene();
  const auto s = small_data();
  bake::TrainSettings ts;
  ts.iterations = 300;
  ts.batch = 256;
  const model::MlpLayout layout{.width = 16, .hidden_layers = 1};
  constexpr int kSteps = 60;

  const SoloRun solo = train_alone(assets, bake::generate_dataset(assets, s), ts, layout, kSteps);
  const model::TransferModel& one = solo.model;
  const std::vector<float>& solo_loss = solo.losses;
  const bake::BandErrors& solo_validation = solo.validation;

  for (int ranks : {2, 4}) {
    std::vector<model::TransferModel> models(static_cast<std::size_t>(ranks));
    std::vector<std::vector<float>> losses(static_cast<std::size_t>(ranks));
    std::vector<bake::BandErrors> validation(static_cast<std::size_t>(ranks));
    std::vector<std::uint64_t> sent(static_cast<std::size_t>(ranks));
    on_ranks(ranks, [&](int r, bake::Communicator& comm) {
      const auto data = bake::generate_dataset(assets, s, {}, {r, ranks});
      models[r] = bake::make_untrained_model(assets, 7, layout, 3);
      bake::Trainer trainer(data, assets, models[r], ts, comm);
      for (int i = 0; i < kSteps; ++i) losses[r].push_back(trainer.step());
      validation[r] = trainer.validate();
      sent[r] = comm.bytes_sent();
    });
    for (int r = 1; r < ranks; ++r) EXPECT_EQ(weights(models[r]), weights(models[0])) << "rank " << r << "'s replica differs";
    EXPECT_EQ(losses[0], solo_loss) << ranks << " ranks: the same batches' losses";
    EXPECT_EQ(weights(models[0]), weights(one)) << ranks << " ranks trained other weights";
    // The same weights; the validation runs over each rank's own samples, in
    // batches of other sizes, and a row of oneDNN's AVX2 products moves in its
    // last bits with the batch's size.
    EXPECT_NEAR(validation[0].total, solo_validation.total, 1e-9 * solo_validation.total);
    // What a step exchanges: the decoder's gradients and the loss (handed
    // over once here; MPI's recursive doubling sends them once per level of
    // the tree, log2 of the ranks), then the latent rows the rank's share of
    // the batch touched (index + 7 floats).
    const double per_step = static_cast<double>(sent[0]) / kSteps;
    const double levels = std::log2(ranks);
    const double decoder = static_cast<double>(one.decoder.params().size()) * sizeof(float) + sizeof(double);
    EXPECT_GT(per_step, decoder);
    EXPECT_LT(per_step, levels * decoder + 3.0 * 256 / ranks * (8 + 7 * 4) + 4096) << "sparse latent rows, at most 3 per sample";
  }
}

// Three ranks do not divide the blocks: each sums its samples in the tree
// alone, then the ranks in rank order. Not the one process's bits, but its
// steps within rounding.
TEST(DistributedTraining, ThreeRanksTakeTheOneProcessStepsWithinRounding) {
  const auto assets = tiny_scene();
  const auto s = small_data();
  bake::TrainSettings ts;
  ts.batch = 256;
  const model::MlpLayout layout{.width = 16, .hidden_layers = 1};
  constexpr int kSteps = 40;
  const SoloRun solo = train_alone(assets, bake::generate_dataset(assets, s), ts, layout, kSteps);
  std::vector<model::TransferModel> models(3);
  on_ranks(3, [&](int r, bake::Communicator& comm) {
    const auto data = bake::generate_dataset(assets, s, {}, {r, 3});
    models[r] = bake::make_untrained_model(assets, 7, layout, 3);
    bake::Trainer trainer(data, assets, models[r], ts, comm);
    for (int i = 0; i < kSteps; ++i) trainer.step();
  });
  EXPECT_EQ(weights(models[1]), weights(models[0]));
  EXPECT_EQ(weights(models[2]), weights(models[0]));
  const double apart = relative_distance(weights(solo.model), weights(models[0]));
  std::printf("[ measured ] 3 ranks, after %d steps: weights %.2e apart (relative)\n", kSteps, apart);
  EXPECT_LT(apart, 1e-5);
}

// Blocks by any other count split the same batch's sums otherwise: the steps
// agree within rounding, not to the bit, so the block count is part of what a
// bake's bits depend on (and one block is the plain batch's sum).
TEST(DistributedTraining, TheBlockCountChangesTheStepsOnlyByRounding) {
  const auto assets = tiny_scene();
  const auto data = bake::generate_dataset(assets, small_data());
  const model::MlpLayout layout{.width = 16, .hidden_layers = 1};
  std::vector<std::vector<float>> w;
  for (int blocks : {1, 8, 64}) {
    bake::TrainSettings ts;
    ts.batch = 256;
    ts.gradient_blocks = blocks;
    auto m = bake::make_untrained_model(assets, 7, layout, 3);
    bake::Trainer trainer(data, assets, m, ts);
    for (int i = 0; i < 20; ++i) trainer.step();
    w.push_back(weights(m));
  }
  for (std::size_t k = 1; k < w.size(); ++k) {
    EXPECT_GT(relative_distance(w[0], w[k]), 0.0) << "the sums' order should show in the last bits";
    EXPECT_LT(relative_distance(w[0], w[k]), 1e-5);
  }
  bake::TrainSettings bad;
  bad.gradient_blocks = 6;
  auto m = bake::make_untrained_model(assets, 7, layout, 3);
  EXPECT_THROW(bake::Trainer(data, assets, m, bad), std::invalid_argument);
}

// A batch smaller than the ranks: a rank often holds none of it and still
// joins every exchange; the replicas stay equal.
TEST(DistributedTraining, ARankWithNoSampleOfTheBatchStillTakesTheStep) {
  const auto assets = tiny_scene();
  auto s = small_data();
  s.points = 200;
  bake::TrainSettings ts;
  ts.batch = 1;
  ts.iterations = 40;
  std::vector<model::TransferModel> models(3);
  on_ranks(3, [&](int r, bake::Communicator& comm) {
    const auto data = bake::generate_dataset(assets, s, {}, {r, 3});
    models[r] = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 8, .hidden_layers = 1}, 5);
    bake::Trainer trainer(data, assets, models[r], ts, comm);
    for (int i = 0; i < ts.iterations; ++i) EXPECT_TRUE(std::isfinite(trainer.step()));
    EXPECT_EQ(trainer.iteration(), ts.iterations);
  });
  EXPECT_EQ(weights(models[0]), weights(models[1]));
  EXPECT_EQ(weights(models[0]), weights(models[2]));
  EXPECT_NE(weights(models[0]), weights(bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 8, .hidden_layers = 1}, 5)));
}

// The whole bake on two ranks: one model, written by rank 0, the
// one-process bake's to the bit; each rank's dataset shard cached under its own name
// and removed after success.
TEST(BakeJob, TwoRanksBakeTheOneProcessModel) {
  TempDir dir("bake_distributed");
  const auto assets = tiny_scene();
  bake::BakeSettings s;
  s.data = small_data();
  s.train.iterations = 400;
  s.train.batch = 256;
  s.layout = {.width = 16, .hidden_layers = 1};
  s.checkpoint_every = 100;
  const auto solo = bake::run_bake(assets, dir.path / "one.tgm", s);

  std::vector<bake::BakeReport> reports(2);
  std::vector<int> sampling_calls(2), training_calls(2);
  const fs::path out = dir.path / "two.tgm";
  s.keep_dataset = true;
  on_ranks(2, [&](int r, bake::Communicator& comm) {
    bake::BakeCallbacks cb;
    cb.sampling = [&](std::size_t, std::size_t, std::span<const double> rates) {
      ++sampling_calls[r];
      EXPECT_EQ(rates.size(), 2u);
    };
    cb.training = [&](int, int, float, std::span<const double>) { ++training_calls[r]; };
    reports[r] = bake::run_bake(assets, out, s, cb, comm);
  });
  EXPECT_EQ(sampling_calls[0], bake::kSamplingRounds);
  EXPECT_EQ(training_calls[0], 400);
  EXPECT_EQ(sampling_calls[1] + training_calls[1], 0) << "progress is shown once, by rank 0";
  for (const auto& r : reports) {
    EXPECT_EQ(r.ranks, 2);
    EXPECT_EQ(r.samples, solo.samples);
    EXPECT_EQ(r.training_samples, solo.training_samples);
    EXPECT_EQ(r.validation.total, reports[0].validation.total);
    EXPECT_EQ(r.sampling_rates.size(), 2u);
  }
  // The same weights; the validation's error sums part by rank, in double,
  // and its products run over each rank's samples (see above).
  EXPECT_NEAR(reports[0].validation.total, solo.validation.total, 1e-9 * solo.validation.total);
  const auto m = model::load_model(out);
  EXPECT_EQ(weights(m), weights(model::load_model(dir.path / "one.tgm"))) << "two ranks baked another model";
  EXPECT_NO_THROW(model::validate_model(m, assets, out));
  EXPECT_FALSE(fs::exists(bake::checkpoint_path(out)));
  EXPECT_TRUE(fs::exists(bake::dataset_cache_path(out, {0, 2})));
  EXPECT_TRUE(fs::exists(bake::dataset_cache_path(out, {1, 2})));

  // --resume with the shards cached: nothing is traced again.
  s.resume = true;
  on_ranks(2, [&](int r, bake::Communicator& comm) { reports[r] = bake::run_bake(assets, out, s, {}, comm); });
  EXPECT_TRUE(reports[0].dataset_from_cache);
  EXPECT_TRUE(reports[1].dataset_from_cache);

  // Baked again by one process: the model written, no cache of any rank count is left.
  s.keep_dataset = false;
  bake::run_bake(assets, out, s);
  for (const auto& e : fs::directory_iterator(dir.path))
    EXPECT_EQ(e.path().filename().string().find("two.tgm.dataset"), std::string::npos) << e.path() << " was left behind";
}

// A shard trained alone would draw batches from samples it does not hold.
TEST(DistributedTraining, AShardTrainedByTheWrongRankIsRefused) {
  const auto assets = tiny_scene();
  auto s = small_data();
  s.points = 100;
  const auto shard = bake::generate_dataset(assets, s, {}, {1, 2});
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 8, .hidden_layers = 1}, 5);
  try {
    bake::Trainer trainer(shard, assets, m, {});
    ADD_FAILURE() << "a shard of two ranks' dataset trained by one process";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rank 1 of 2's shard, but this trainer is rank 0 of 1"), std::string::npos) << e.what();
  }
}

// LatentUpdates::Touched: a step moves the latent rows its batch touched and
// no other (their moments and values stay as they were).
TEST(DistributedTraining, TouchedRowUpdatesMoveOnlyTheBatchsRows) {
  const auto assets = tiny_scene();
  auto s = small_data();
  s.points = 200;
  const auto data = bake::generate_dataset(assets, s);
  bake::TrainSettings ts;
  ts.batch = 8;
  ts.latent_updates = bake::LatentUpdates::Touched;
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 8, .hidden_layers = 1}, 5);
  bake::Trainer trainer(data, assets, m, ts);
  for (int i = 0; i < 5; ++i) trainer.step();
  const auto before = m.meshes;
  trainer.step();
  std::size_t moved = 0, rows = 0;
  for (std::size_t mesh = 0; mesh < m.meshes.size(); ++mesh) {
    const auto& a = before[mesh].latents;
    const auto& b = m.meshes[mesh].latents;
    for (std::uint32_t r = 0; r < a.rows(); ++r, ++rows)
      moved += !std::equal(a.row(r), a.row(r) + 7, b.row(r));
  }
  EXPECT_GT(moved, 0u);
  EXPECT_LE(moved, 3u * 8) << "a batch of 8 touches at most 24 rows; " << rows << " in the model";
}

// Touched-row updates on two ranks take the one process's steps too, bit for
// bit: every rank moves the rows any rank's samples touched.
TEST(DistributedTraining, TouchedRowUpdatesOnTwoRanksTakeTheOneProcessSteps) {
  const auto assets = tiny_scene();
  const auto s = small_data();
  bake::TrainSettings ts;
  ts.batch = 256;
  ts.latent_updates = bake::LatentUpdates::Touched;
  const model::MlpLayout layout{.width = 16, .hidden_layers = 1};
  const SoloRun solo = train_alone(assets, bake::generate_dataset(assets, s), ts, layout, 40);

  std::vector<model::TransferModel> models(2);
  on_ranks(2, [&](int r, bake::Communicator& comm) {
    const auto data = bake::generate_dataset(assets, s, {}, {r, 2});
    models[r] = bake::make_untrained_model(assets, 7, layout, 3);
    bake::Trainer trainer(data, assets, models[r], ts, comm);
    for (int i = 0; i < 40; ++i) trainer.step();
  });
  EXPECT_EQ(weights(models[0]), weights(models[1]));
  EXPECT_EQ(weights(models[0]), weights(solo.model));
}

// The training steps do not depend on how many threads oneDNN's products
// use: each gradient block is multiplied on one thread (the blocks run in
// parallel), so the bake's bits are the same with --threads 1 or 2. At AVX2
// oneDNN's sgemm splits a product's rows by thread count and rounds them
// differently; CTest runs this suite capped there too (isa_avx2).
TEST(DistributedTraining, TheStepsAreTheSameWhateverTheGemmThreadCount) {
  const auto assets = tiny_scene();
  const auto data = bake::generate_dataset(assets, small_data());
  bake::TrainSettings ts;
  ts.iterations = 100;
  ts.batch = 2048;
  const model::MlpLayout layout{};  // the bake's own: 3 x 128
  std::vector<std::vector<float>> trained;
  for (int threads : {1, 2}) {
    model::set_gemm_threads(threads);
    model::TransferModel m = bake::make_untrained_model(assets, 7, layout, 3);
    bake::Trainer trainer(data, assets, m, ts);
    for (int i = 0; i < 6; ++i) trainer.step();
    trained.push_back(weights(m));
  }
  model::set_gemm_threads(0);
  EXPECT_EQ(trained[0], trained[1]) << "relative distance " << relative_distance(trained[0], trained[1]);
}
