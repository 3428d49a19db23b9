// What `render` and `eval` measure: a still view's image on the quality path
// is the mean of its whole temporal window of jittered frames, however many
// of the last frames are timed. Until 2026-11-27 only the timed frames (3 by
// default) made an image, so `render` averaged 3 of the quality preset's 16
// jittered samples a pixel and thin features (window muntins) stayed aliased.
#include <gtest/gtest.h>

#include <memory>

#include "engine/image/metrics.h"
#include "eval/method_runs.h"
#include "model/transfer_model.h"

using namespace transgi;

namespace {
const std::string kScene = std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf";
constexpr int kW = 48, kH = 27, kWindow = 8, kFrames = 24;

// What both methods' runs share: the frames, how many are timed, a 4^3
// grid, no progress bar.
template <class Options>
Options run_options(int timing_frames) {
  Options o;
  o.frames = kFrames;
  o.timing_frames = timing_frames;
  o.placement.scene_dims = glm::ivec3(4);
  o.progress = false;
  return o;
}

eval::MethodRun transgi_run(int temporal_window, int timing_frames) {
  auto t = run_options<eval::TransgiRunOptions>(timing_frames);
  t.settings.direct_spp = 0;
  t.settings.temporal_window = temporal_window;
  eval::LoadedScene scene = eval::load_scene(kScene, "", 2);
  // No baked model: every surface is shaded diffusely from the probes.
  return eval::run_transgi(scene, std::make_shared<const model::TransferModel>(), kW, kH, t);
}

eval::MethodRun ddgi_run(int temporal_window, int timing_frames) {
  auto d = run_options<eval::DdgiRunOptions>(timing_frames);
  d.render.direct_spp = 0;
  d.render.temporal_window = temporal_window;
  eval::LoadedScene scene = eval::load_scene(kScene, "", 2);
  return eval::run_ddgi(scene, kW, kH, d);
}

double rmse(const engine::image::ImageRGB& a, const engine::image::ImageRGB& b) {
  return engine::image::compare_images(a, b).rmse;
}
}  // namespace

TEST(MethodRuns, AStillViewAveragesItsWholeTemporalWindowHoweverFewFramesAreTimed) {
  const eval::MethodRun one_timed = transgi_run(kWindow, 1), all_timed = transgi_run(kWindow, kWindow);
  const eval::MethodRun no_window = transgi_run(1, 1);
  // The jittered frames differ at the box's edges, so the window is seen...
  EXPECT_GT(rmse(all_timed.gi, no_window.gi), 1e-4) << "the window's frames should differ from the last frame alone";
  // ... and it is the same window whether 1 or all of its frames are timed
  // (the runs are deterministic: the same frames, seeds and probes).
  EXPECT_EQ(rmse(one_timed.gi, all_timed.gi), 0.0) << "TransGI: the image depends on --timing-frames";
}

TEST(MethodRuns, DdgiAveragesItsWholeTemporalWindowHoweverFewFramesAreTimed) {
  const eval::MethodRun one_timed = ddgi_run(kWindow, 1), all_timed = ddgi_run(kWindow, kWindow);
  const eval::MethodRun no_window = ddgi_run(1, 1);
  EXPECT_GT(rmse(all_timed.gi, no_window.gi), 1e-4) << "the window's frames should differ from the last frame alone";
  EXPECT_EQ(rmse(one_timed.gi, all_timed.gi), 0.0) << "DDGI: the image depends on --timing-frames";
}
