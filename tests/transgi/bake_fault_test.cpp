// Faults during a bake (issue 13, item 5), on the real `transgi bake`
// process: SIGKILL at random moments leaves the previous model (or, once the
// bake has renamed its new one into place, that whole new model), and
// --resume then finishes with a model that validates; a full disk
// (RLIMIT_FSIZE) fails with a message naming the file and leaves the old
// model whole.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

#include "engine/ecs/world.h"
#include "engine/math/rng.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_assets.h"
#include "model/model_file.h"
#include "child_process.h"

namespace fs = std::filesystem;
using namespace child_process;

namespace {

const std::string kScene = std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf";

// A bake small enough to finish in about a second; `seed` changes the model.
std::vector<std::string> bake_args(const fs::path& out, int seed, bool resume) {
  std::vector<std::string> a{TRANSGI_BINARY, "bake", "--scene", kScene, "--out", out.string(), "--points", "300", "--dirs", "64",
                             "--outgoing", "4", "--iters", "1200", "--batch", "256", "--width", "16", "--depth", "1",
                             "--threads", "1", "--seed", std::to_string(seed)};
  if (resume) a.push_back("--resume");
  return a;
}

void expect_valid_model(const fs::path& p) {
  engine::ecs::World world;
  engine::scene::load_gltf(world, kScene);
  const transgi::model::TransferModel m = transgi::model::load_model(p);
  transgi::model::validate_model(m, world.resource<engine::scene::SceneAssets>(), p);
}

class BakeFaults : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("transgi_bake_faults_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    out_ = dir_ / "model.tgm";
    // The good model a user already has.
    ASSERT_EQ(wait_exit(spawn(bake_args(out_, 1, false), dir_ / "first.log")), 0) << "the first bake failed";
    good_ = bytes_of(out_);
    ASSERT_FALSE(good_.empty());
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_, out_;
  std::vector<char> good_;
};

}  // namespace

TEST_F(BakeFaults, KilledAtRandomMomentsTheOldModelStaysAndResumeFinishes) {
  // How long an uninterrupted bake takes, to spread the kills over it.
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(wait_exit(spawn(bake_args(dir_ / "timing.tgm", 2, false), dir_ / "timing.log")), 0);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  engine::math::Pcg32 rng(13, 5);
  // 20 kills that land mid-bake. A bake that finishes before its kill (the
  // machine got faster, or a resumed bake had little left) is checked too;
  // a fresh one teaches the shortest bake time, so later delays stay inside it.
  int killed = 0, finished = 0;
  for (int trial = 0; killed < 20 && trial < 80; ++trial) {
    // Odd trials resume from what the last kill left.
    const auto started = std::chrono::steady_clock::now();
    const pid_t pid = spawn(bake_args(out_, 2, /*resume=*/trial % 2 == 1), dir_ / "trial.log");
    std::this_thread::sleep_for(std::chrono::duration<double>(0.9 * seconds * rng.next_float()));
    ::kill(pid, SIGKILL);
    const int code = wait_exit(pid);
    if (code == -SIGKILL && bytes_of(out_) != good_) {
      // Killed after the new model was renamed into place, while the bake
      // cleaned up: the work was done, and the model must be whole.
      ++finished;
      expect_valid_model(out_);
      good_ = bytes_of(out_);
    } else if (code == -SIGKILL) {
      ++killed;
    } else {
      ++finished;
      ASSERT_EQ(code, 0) << "trial " << trial;
      expect_valid_model(out_);
      good_ = bytes_of(out_);
      if (trial % 2 == 0)  // a fresh bake's time, not a resumed one's remainder
        seconds = std::min(seconds, std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    }
  }
  std::printf("[ measured ] %d kills mid-bake (bake %.2f s at its shortest); %d bakes finished before their kill, each valid\n",
              killed, seconds, finished);
  EXPECT_EQ(killed, 20) << "fewer than 20 kills landed mid-bake in 80 trials";
  ASSERT_EQ(wait_exit(spawn(bake_args(out_, 2, true), dir_ / "resume.log")), 0) << "--resume after the kills failed";
  EXPECT_NO_THROW(expect_valid_model(out_));
}

TEST_F(BakeFaults, AFullDiskFailsNamingTheFileAndLeavesTheOldModel) {
  // 4 KB per file: the dataset cache, checkpoints and the model all exceed it.
  const int code = wait_exit(spawn(bake_args(out_, 3, false), dir_ / "full.log", 4096));
  const std::vector<char> log = bytes_of(dir_ / "full.log");
  const std::string text(log.begin(), log.end());
  EXPECT_NE(code, 0) << "the bake must fail when it cannot write";
  EXPECT_GT(code, 0) << "it must fail with an error, not die of a signal; log:\n" << text;
  EXPECT_NE(text.find("model.tgm"), std::string::npos) << "the message must name the file; log:\n" << text;
  std::printf("[ measured ] full disk: exit %d, %s", code, text.substr(text.rfind('\n', text.size() - 2) + 1).c_str());
  EXPECT_EQ(bytes_of(out_), good_) << "the old model changed";
  for (const auto& e : fs::directory_iterator(dir_)) EXPECT_NE(e.path().extension(), ".tmp") << "a torn temporary was left: " << e.path();
}
