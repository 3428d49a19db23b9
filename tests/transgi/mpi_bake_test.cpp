// `mpirun -n 2 transgi bake` (issue 35), the real processes through Open MPI:
// the model as good as one process's, progress shown once, and a rank killed
// with SIGKILL mid-training ends the job without a torn checkpoint or model,
// after which --resume finishes. Built where the MPI bake is on
// (TRANSGI_WITH_MPI); the same logic without MPI: bake_distributed_test.cpp.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake/bake_job.h"
#include "child_process.h"
#include "engine/ecs/world.h"
#include "engine/math/rng.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_assets.h"
#include "model/model_file.h"

namespace fs = std::filesystem;
using namespace child_process;

namespace {

const std::string kScene = std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf";

std::vector<std::string> bake_args(const fs::path& out, int iterations, bool resume) {
  std::vector<std::string> a{TRANSGI_BINARY, "bake", "--scene", kScene, "--out", out.string(), "--points", "400", "--dirs", "64",
                             "--outgoing", "4", "--iters", std::to_string(iterations), "--batch", "256", "--width", "16",
                             "--depth", "1", "--threads", "1"};
  if (resume) a.push_back("--resume");
  return a;
}

// --oversubscribe: a CI machine with one core still runs two ranks.
std::vector<std::string> on_ranks(int n, std::vector<std::string> args) {
  args.insert(args.begin(), {TRANSGI_MPIEXEC, "--oversubscribe", "-n", std::to_string(n)});
  return args;
}

double validation_rmse(const fs::path& model) {
  return nlohmann::json::parse(transgi::model::load_model(model).metrics_json).at("validation_rmse").get<double>();
}

const engine::scene::SceneAssets& scene_assets() {
  static engine::ecs::World world;
  static const bool loaded = (engine::scene::load_gltf(world, kScene), true);
  (void)loaded;
  return world.resource<engine::scene::SceneAssets>();
}

// The `transgi` processes mpirun started (its children, by /proc).
std::vector<pid_t> ranks_of(pid_t mpirun) {
  std::vector<pid_t> ranks;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string stat = text_of(e.path() / "stat");
    const auto close = stat.rfind(')');
    if (close == std::string::npos || stat.find("(transgi)") == std::string::npos) continue;
    int parent = 0;
    char state = 0;
    if (std::sscanf(stat.c_str() + close + 1, " %c %d", &state, &parent) == 2 && parent == mpirun)
      ranks.push_back(static_cast<pid_t>(std::stoi(name)));
  }
  return ranks;
}

// Whether the process still runs (a zombie that nobody reaped yet does not).
bool running(pid_t pid) {
  const std::string stat = text_of(fs::path("/proc") / std::to_string(pid) / "stat");
  const auto close = stat.rfind(')');
  return close != std::string::npos && close + 2 < stat.size() && stat[close + 2] != 'Z' && stat[close + 2] != 'X';
}

bool wait_for_text(const fs::path& log, const std::string& text, pid_t still_running, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    if (text_of(log).find(text) != std::string::npos) return true;
    if (::waitpid(still_running, nullptr, WNOHANG) != 0) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

class MpiBake : public ::testing::Test {
 protected:
  void SetUp() override {
    // mpirun refuses to start as root without both (CI containers run as root).
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    dir_ = fs::temp_directory_path() / ("transgi_mpi_bake_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

}  // namespace

// The gradients are summed in one fixed tree whatever the rank count
// (bake/trainer.h), so 2 and 4 ranks bake the one process's model, every
// weight equal to the bit (issue 35 asks for validation RMSE within 2 %).
TEST_F(MpiBake, TwoAndFourRanksBakeTheOneProcessModelBitForBit) {
  ASSERT_EQ(wait_exit(spawn(bake_args(dir_ / "one.tgm", 1200, false), dir_ / "one.log")), 0) << text_of(dir_ / "one.log");
  ASSERT_EQ(wait_exit(spawn(on_ranks(2, bake_args(dir_ / "two.tgm", 1200, false)), dir_ / "two.log")), 0)
      << text_of(dir_ / "two.log");
  ASSERT_EQ(wait_exit(spawn(on_ranks(4, bake_args(dir_ / "four.tgm", 1200, false)), dir_ / "four.log")), 0)
      << text_of(dir_ / "four.log");
  const std::string log = text_of(dir_ / "two.log");
  EXPECT_NE(log.find("baking on 2 ranks"), std::string::npos) << log;
  EXPECT_EQ(log.find("baked "), log.rfind("baked ")) << "rank 0 alone reports: " << log;
  EXPECT_NE(log.find("ranks:    2;"), std::string::npos) << log;
  const double one = validation_rmse(dir_ / "one.tgm"), two = validation_rmse(dir_ / "two.tgm"),
               four = validation_rmse(dir_ / "four.tgm");
  std::printf("[ measured ] validation RMSE: one process %.7f, two ranks %.7f, four ranks %.7f\n", one, two, four);
  const auto weights = [](const fs::path& p) {
    const auto m = transgi::model::load_model(p);
    std::vector<float> w = m.decoder.params();
    for (const auto& mesh : m.meshes) w.insert(w.end(), mesh.latents.values.begin(), mesh.latents.values.end());
    return w;
  };
  const auto w1 = weights(dir_ / "one.tgm");
  EXPECT_EQ(weights(dir_ / "two.tgm"), w1) << "2 ranks trained another model";
  EXPECT_EQ(weights(dir_ / "four.tgm"), w1) << "4 ranks trained another model";
  EXPECT_NEAR(two, one, 1e-9 * one);  // the same weights; see bake_distributed_test.cpp
  EXPECT_NO_THROW(transgi::model::validate_model(transgi::model::load_model(dir_ / "two.tgm"), scene_assets(), dir_ / "two.tgm"));
  EXPECT_FALSE(fs::exists(transgi::bake::dataset_cache_path(dir_ / "two.tgm", {0, 2})));
  EXPECT_FALSE(fs::exists(transgi::bake::dataset_cache_path(dir_ / "two.tgm", {1, 2})));
}

// TRANSGI_MPI_KILL_TRIALS sets the number of kills (3 in the suite; the
// 10-trial run is in docs/bake.md). Each trial resumes from what the last left.
TEST_F(MpiBake, ARankKilledMidTrainingEndsTheJobWithoutATornFileAndResumeFinishes) {
  const char* env = std::getenv("TRANSGI_MPI_KILL_TRIALS");
  const int trials = env ? std::max(1, std::atoi(env)) : 3;
  const fs::path out = dir_ / "model.tgm";
  constexpr int kIterations = 4000;

  // How long the training of an uninterrupted job takes, to spread the kills over it.
  const fs::path timing_log = dir_ / "timing.log";
  const pid_t timing = spawn(on_ranks(2, bake_args(dir_ / "timing.tgm", kIterations, false)), timing_log);
  ASSERT_TRUE(wait_for_text(timing_log, "training", timing, 60)) << text_of(timing_log);
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(wait_exit(timing), 0) << text_of(timing_log);
  const double training_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  engine::math::Pcg32 rng(35, 1);
  int killed = 0, finished = 0, resumed = 0;
  for (int attempt = 0; killed < trials && attempt < 4 * trials; ++attempt) {
    const fs::path log = dir_ / ("trial" + std::to_string(attempt) + ".log");
    const pid_t mpirun = spawn(on_ranks(2, bake_args(out, kIterations, attempt > 0)), log);
    ASSERT_TRUE(wait_for_text(log, "training", mpirun, 60)) << "trial " << attempt << ": no training\n" << text_of(log);
    std::this_thread::sleep_for(std::chrono::duration<double>(0.8 * training_seconds * rng.next_float()));
    const std::vector<pid_t> ranks = ranks_of(mpirun);
    if (!ranks.empty()) ::kill(ranks[rng.next_u32() % ranks.size()], SIGKILL);
    const int code = wait_exit(mpirun);
    const std::string printed = text_of(log);
    resumed += printed.find("resuming from the checkpoint") != std::string::npos;
    // It finished before the kill (a resumed job had little left), or the kill
    // came after rank 0 had renamed the model into place: a whole model.
    if (code == 0 || fs::exists(out)) {
      ++finished;
      EXPECT_NO_THROW(transgi::model::validate_model(transgi::model::load_model(out), scene_assets(), out));
      fs::remove(out);
      continue;
    }
    ++killed;
    EXPECT_EQ(ranks.size(), 2u) << "trial " << attempt;
    EXPECT_NE(printed.find("signal 9"), std::string::npos) << "trial " << attempt << ": no word of the killed rank\n" << printed;
    for (pid_t r : ranks) EXPECT_FALSE(running(r)) << "trial " << attempt << ": rank " << r << " outlived the job";
    // No torn file: the checkpoint, if any, is whole; no model before the end.
    if (fs::exists(transgi::bake::checkpoint_path(out))) {
      EXPECT_TRUE(transgi::bake::checkpoint_iteration(out, scene_assets()).has_value()) << "trial " << attempt << ": torn checkpoint";
    }
  }
  EXPECT_EQ(killed, trials);
  const fs::path last = dir_ / "resume.log";
  ASSERT_EQ(wait_exit(spawn(on_ranks(2, bake_args(out, kIterations, true)), last)), 0) << text_of(last);
  EXPECT_NO_THROW(transgi::model::validate_model(transgi::model::load_model(out), scene_assets(), out));
  std::printf("[ measured ] %d kills of a random rank mid-training (training %.2f s uninterrupted); %d jobs finished "
              "before their kill; %d resumed from a checkpoint\n",
              killed, training_seconds, finished, resumed);
}

// A rank that fails alone (here: its shard cache cannot be written) says so
// with its rank and the file, and ends the job instead of leaving the other
// rank waiting in an exchange.
TEST_F(MpiBake, ARankThatFailsAloneEndsTheJobNamingItselfAndTheFile) {
  const fs::path out = dir_ / "model.tgm";
  fs::create_directories(transgi::bake::dataset_cache_path(out, {1, 2}));  // a folder where rank 1 writes its shard
  const fs::path log = dir_ / "fail.log";
  const auto started = std::chrono::steady_clock::now();
  const pid_t mpirun = spawn(on_ranks(2, bake_args(out, 400, false)), log);
  int code = 0;
  while (::waitpid(mpirun, &code, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() - started > std::chrono::seconds(60)) {
      for (pid_t r : ranks_of(mpirun)) ::kill(r, SIGKILL);
      ::kill(mpirun, SIGKILL);
      ::waitpid(mpirun, nullptr, 0);
      FAIL() << "the job hung:\n" << text_of(log);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const std::string printed = text_of(log);
  EXPECT_FALSE(WIFEXITED(code) && WEXITSTATUS(code) == 0) << printed;
  EXPECT_NE(printed.find("rank 1 of 2: " + transgi::bake::dataset_cache_path(out, {1, 2}).string()), std::string::npos) << printed;
  EXPECT_FALSE(fs::exists(out));
}
