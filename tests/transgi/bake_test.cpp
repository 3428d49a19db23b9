// Training and the model file, on a tiny scene made in the test.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "bake/trainer.h"
#include "engine/core/fnv1a.h"
#include "engine/scene/procedural.h"
#include "model/model_file.h"
#include "bake_fixtures.h"

using namespace transgi;
using namespace engine;
using namespace bake_fixtures;
namespace fs = std::filesystem;

namespace {

// Points by area, capped per vertex: a 200 m ground plane of 4 vertices
// (40,000 m^2) beside a 10 m^2 mesh of 1,000 vertices. By area alone the plane
// takes all but the floor of 32; capped at 64 a vertex it takes 256 and the
// detailed mesh the remaining 9,744. A cap that binds no mesh changes nothing.
TEST(BakeDataset, ACoarseGroundPlaneDoesNotTakeThePointsFromTheDetailedMeshes) {
  bake::DatasetSettings s;
  s.points = 10000;
  s.min_points_per_mesh = 32;
  const std::vector<double> area = {40000.0, 10.0, 0.0};
  const std::vector<std::size_t> vertices = {4, 1000, 3};
  s.max_points_per_vertex = 0;
  const auto by_area = bake::points_per_mesh(area, vertices, s);
  EXPECT_EQ(by_area, (std::vector<int>{9998, 32, 0})) << "by area alone: " << by_area[0] << ", " << by_area[1];
  s.max_points_per_vertex = 64;
  const auto capped = bake::points_per_mesh(area, vertices, s);
  EXPECT_EQ(capped, (std::vector<int>{256, 9744, 0})) << "capped: " << capped[0] << ", " << capped[1];
  s.max_points_per_vertex = 8192;  // the default: 32,768 for the plane, which 10,000 points do not reach
  EXPECT_EQ(bake::points_per_mesh(area, vertices, s), by_area);
  s.points = 131072;  // the CLI's default points: now the cap binds
  EXPECT_EQ(bake::points_per_mesh(area, vertices, s), (std::vector<int>{32768, 98304, 0}));
}

void expect_load_error(const fs::path& p, const std::string& fragment) {
  try {
    model::load_model(p);
    ADD_FAILURE() << "expected ModelFileError containing '" << fragment << "'";
  } catch (const model::ModelFileError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << "must name the file: " << e.what();
  }
}

}  // namespace

TEST(Dataset, IsDeterministicForASeed) {
  const auto assets = tiny_scene();
  auto s = tiny_data();
  s.points = 100;
  s.rays = 64;
  const auto a = bake::generate_dataset(assets, s), b = bake::generate_dataset(assets, s);
  ASSERT_EQ(a.targets.size(), b.targets.size());
  EXPECT_EQ(a.targets, b.targets);
  EXPECT_GT(a.validation_count(), 0u);
  EXPECT_EQ(a.training_count % 4, 0u) << "split by point: whole groups of 4 outgoing directions";
}

TEST(Trainer, LowersValidationErrorWellBelowAConstantPredictor) {
  const auto assets = tiny_scene();
  // The paper's targets, albedo included: a constant cannot follow their
  // albedo's variation (demodulated, this scene's band 0 is nearly constant).
  auto settings = tiny_data();
  settings.demodulate = false;
  const auto data = bake::generate_dataset(assets, settings);
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 64, .hidden_layers = 3}, 3);
  bake::TrainSettings ts;
  ts.iterations = 1500;
  ts.batch = 256;
  ts.learning_rate = 3e-3f;
  bake::Trainer trainer(data, assets, m, ts);
  const auto constant = trainer.constant_predictor();
  const auto before = trainer.validate();
  for (int i = 0; i < ts.iterations; ++i) trainer.step();
  const auto after = trainer.validate();
  EXPECT_EQ(trainer.rollbacks(), 0);
  EXPECT_LT(after.total, 0.5 * constant.total) << "constant predictor RMSE " << constant.total << ", trained " << after.total
                                               << " (untrained " << before.total << ")";
  EXPECT_LT(after.rmse[0], 0.5 * constant.rmse[0]) << "band 0";
  EXPECT_LT(after.rmse[1], 0.5 * constant.rmse[1]) << "band 1";
  EXPECT_LT(after.rmse[4], 0.8 * constant.rmse[4]) << "band 4";
}

TEST(Trainer, NonFiniteValuesRollBackAndNeverReachTheWeights) {
  const auto assets = tiny_scene();
  auto s = tiny_data();
  s.points = 150;
  s.rays = 64;
  auto data = bake::generate_dataset(assets, s);
  // Poison one in 20 training targets: most batches of 64 then contain one.
  for (std::size_t i = 0; i < data.training_count; i += 20) data.targets[i * bake::kTransferValues] = std::numeric_limits<float>::infinity();
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 32, .hidden_layers = 2}, 3);
  bake::TrainSettings ts;
  ts.iterations = 50;
  ts.batch = 64;
  bake::Trainer trainer(data, assets, m, ts);
  for (int i = 0; i < 50; ++i) trainer.step();
  EXPECT_GT(trainer.rollbacks(), 0) << "the guard must have fired";
  EXPECT_LT(trainer.current_learning_rate(), ts.learning_rate) << "each rollback lowers the learning rate";
  for (float p : m.decoder.params()) ASSERT_TRUE(std::isfinite(p));
  for (const auto& mesh : m.meshes)
    for (float v : mesh.latents.values) ASSERT_TRUE(std::isfinite(v));
}

TEST(ModelFile, RoundTripsExactly) {
  TempDir d;
  const auto assets = tiny_scene();
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 16, .hidden_layers = 1}, 9);
  m.bake_settings_json = R"({"points": 600})";
  m.metrics_json = R"({"rmse": 0.1})";
  m.demodulated = true;
  model::save_model(d.path / "m.tgm", m);
  const auto back = model::load_model(d.path / "m.tgm");
  EXPECT_TRUE(back.demodulated);
  EXPECT_EQ(back.decoder.layout(), m.decoder.layout());
  EXPECT_EQ(back.decoder.params(), m.decoder.params());
  ASSERT_EQ(back.meshes.size(), 2u);
  EXPECT_EQ(back.meshes[1].latents.values, m.meshes[1].latents.values);
  EXPECT_EQ(back.meshes[1].latents.vertex_to_latent, m.meshes[1].latents.vertex_to_latent);
  EXPECT_EQ(back.metrics_json, m.metrics_json);
  EXPECT_NO_THROW(model::validate_model(back, assets, d.path / "m.tgm"));
}

// The transfer masks a mesh's own surfaces within the bake's visibility
// distance; shading adds their light back out to the same distance, so the
// fraction travels with the model (in its bake settings). A model whose
// settings do not say was baked with the default; a value that is not a
// distance fraction is an error naming it.
TEST(ModelFile, TheVisibilityFractionTravelsWithTheModel) {
  TempDir d;
  const auto assets = tiny_scene();
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 16, .hidden_layers = 1}, 9);
  const auto reload = [&](const std::string& settings) {
    m.bake_settings_json = settings;
    model::save_model(d.path / "m.tgm", m);
    return model::load_model(d.path / "m.tgm");
  };
  EXPECT_FLOAT_EQ(reload(R"({"points": 600, "visibility_fraction": 0.25})").visibility_fraction, 0.25f);
  EXPECT_FLOAT_EQ(reload(R"({"points": 600})").visibility_fraction, model::kDefaultVisibilityFraction);
  EXPECT_FLOAT_EQ(reload("not json").visibility_fraction, model::kDefaultVisibilityFraction);
  const auto back = reload(R"({"visibility_fraction": 0.25})");
  const engine::scene::MeshAsset& mesh = *assets.meshes[0];
  EXPECT_FLOAT_EQ(back.self_masked_within(mesh), 0.25f * glm::length(mesh.bounds_max - mesh.bounds_min));
  for (const char* bad : {R"({"visibility_fraction": "half"})", R"({"visibility_fraction": -1})"}) {
    try {
      reload(bad);
      ADD_FAILURE() << bad << " loaded";
    } catch (const model::ModelFileError& e) {
      EXPECT_NE(std::string(e.what()).find("visibility_fraction"), std::string::npos) << e.what();
    }
  }
}

TEST(ModelFile, AFormatOneFileLoadsAsNotDemodulated) {
  // Format 1 (before issue 37) ends at the metrics, with no flags word: its
  // decoder predicts the transfer with the albedo in it.
  TempDir d;
  const auto assets = tiny_scene();
  auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 16, .hidden_layers = 1}, 9);
  m.demodulated = true;
  model::save_model(d.path / "v2.tgm", m);
  std::ifstream in(d.path / "v2.tgm", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string payload = bytes.substr(24, bytes.size() - 24 - 4);  // without the flags
  engine::core::Fnv1a f;
  f.bytes(payload.data(), payload.size());
  const std::uint32_t version = 1;
  const std::uint64_t size = payload.size(), checksum = f.h;
  std::string v1 = bytes.substr(0, 4);
  v1.append(reinterpret_cast<const char*>(&version), 4);
  v1.append(reinterpret_cast<const char*>(&size), 8);
  v1.append(reinterpret_cast<const char*>(&checksum), 8);
  v1 += payload;
  std::ofstream(d.path / "v1.tgm", std::ios::binary) << v1;
  const auto back = model::load_model(d.path / "v1.tgm");
  EXPECT_FALSE(back.demodulated);
  EXPECT_EQ(back.decoder.params(), m.decoder.params());
}

TEST(ModelFile, RejectsTruncatedCorruptNewerAndStaleFiles) {
  TempDir d;
  const auto assets = tiny_scene();
  const auto m = bake::make_untrained_model(assets, 7, model::MlpLayout{.width = 16, .hidden_layers = 1}, 9);
  const fs::path good = d.path / "good.tgm";
  model::save_model(good, m);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream(d.path / name, std::ios::binary) << content;
    return d.path / name;
  };
  expect_load_error(write("cut.tgm", bytes.substr(0, bytes.size() / 2)), "truncated");
  expect_load_error(write("tiny.tgm", bytes.substr(0, 10)), "truncated");
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x40;
  expect_load_error(write("flip.tgm", flipped), "checksum");
  std::string newer = bytes;
  newer[4] = static_cast<char>(model::kModelFormatVersion + 1);
  expect_load_error(write("newer.tgm", newer), "newer TransGI");
  expect_load_error(write("junk.tgm", std::string(64, 'x')), "bad magic");
  expect_load_error(d.path / "absent.tgm", "not found");

  auto changed = tiny_scene();
  changed.materials[1].roughness_factor = 0.6f;  // the sphere's material changed after the bake
  try {
    model::validate_model(model::load_model(good), changed, good);
    ADD_FAILURE() << "expected a stale-model error";
  } catch (const model::ModelFileError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("stale"), std::string::npos) << msg;
    EXPECT_NE(msg.find("mesh 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("transgi bake"), std::string::npos) << "must say what to do: " << msg;
  }
}

// ---- the bake job: resume after an interruption, never a torn output ----------

#include "bake/bake_job.h"

namespace {
struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};
bake::BakeSettings small_bake() {
  bake::BakeSettings s;
  s.data = tiny_data();
  s.data.points = 300;
  s.data.rays = 64;
  s.train.iterations = 600;
  s.train.batch = 64;
  s.layout.width = 16;
  s.layout.hidden_layers = 1;
  s.checkpoint_every = 200;
  return s;
}
}  // namespace

TEST(BakeJob, ResumeContinuesFromTheLastCheckpointAndReusesTheDataset) {
  TempDir d;
  const auto assets = tiny_scene();
  const fs::path out = d.path / "m.tgm";
  auto s = small_bake();
  bake::BakeCallbacks kill_at_450;
  kill_at_450.training = [](int it, int, float, std::span<const double>) {
    if (it == 450) throw Interrupted();
  };
  EXPECT_THROW(bake::run_bake(assets, out, s, kill_at_450), Interrupted);
  EXPECT_FALSE(fs::exists(out)) << "no model is written before training finishes";
  EXPECT_TRUE(fs::exists(bake::dataset_cache_path(out)));
  EXPECT_TRUE(fs::exists(bake::checkpoint_path(out)));

  s.resume = true;
  const auto report = bake::run_bake(assets, out, s);
  EXPECT_TRUE(report.dataset_from_cache);
  EXPECT_EQ(report.resumed_from, 400) << "the last checkpoint before the interruption";
  EXPECT_EQ(report.iterations, 600);
  const auto m = model::load_model(out);
  EXPECT_NO_THROW(model::validate_model(m, assets, out));
  EXPECT_FALSE(fs::exists(bake::checkpoint_path(out))) << "checkpoints are cleaned up after success";
}

TEST(BakeJob, AKilledBakeLeavesTheOldModelIntact) {
  TempDir d;
  const auto assets = tiny_scene();
  const fs::path out = d.path / "m.tgm";
  auto s = small_bake();
  s.train.iterations = 200;
  bake::run_bake(assets, out, s);
  std::ifstream before_in(out, std::ios::binary);
  const std::string before((std::istreambuf_iterator<char>(before_in)), std::istreambuf_iterator<char>());

  s.train.iterations = 600;
  s.data.seed = 99;
  bake::BakeCallbacks kill;
  kill.training = [](int it, int, float, std::span<const double>) {
    if (it == 300) throw Interrupted();
  };
  EXPECT_THROW(bake::run_bake(assets, out, s, kill), Interrupted);
  std::ifstream after_in(out, std::ios::binary);
  const std::string after((std::istreambuf_iterator<char>(after_in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(before, after) << "the previous model must survive an interrupted bake byte for byte";
  EXPECT_NO_THROW(model::load_model(out));
}
