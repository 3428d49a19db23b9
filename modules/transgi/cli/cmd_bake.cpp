#include <cstdio>
#include <cstdlib>
#include <span>

#include "bake/bake_job.h"
#include "cli/args.h"
#include "cli/commands.h"
#include "engine/core/progress.h"
#include "engine/image/svg_plot.h"
#include "engine/io/atomic_file.h"
#include "engine/jobs/job_system.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_assets.h"

namespace transgi::cli {

int run_bake(const std::vector<std::string>& argv) {
  const Args args("bake", argv,
                  {"scene", "out", "points", "dirs", "outgoing", "iters", "batch", "lr", "latent-dim", "width", "depth",
                   "threads", "seed", "curve", "max-points-per-vertex"},
                  {"resume", "keep-dataset"});
  bake::BakeSettings s;
  const std::string scene_path = args.str("scene");
  const std::string out = args.str("out");
  s.data.points = static_cast<int>(args.integer("points", 1, 100'000'000, s.data.points));
  s.data.rays = static_cast<int>(args.integer("dirs", 1, 1'000'000, s.data.rays));
  s.data.max_points_per_vertex =
      static_cast<int>(args.integer("max-points-per-vertex", 0, 100'000'000, s.data.max_points_per_vertex));
  s.data.outgoing_per_point = static_cast<int>(args.integer("outgoing", 1, 256, s.data.outgoing_per_point));
  s.train.iterations = static_cast<int>(args.integer("iters", 0, 100'000'000, s.train.iterations));
  s.train.batch = static_cast<int>(args.integer("batch", 1, 1 << 20, s.train.batch));
  s.train.learning_rate = static_cast<float>(args.number("lr", 1e-7, 1.0, s.train.learning_rate));
  s.latent_dim = static_cast<int>(args.integer("latent-dim", 0, 256, s.latent_dim));
  s.layout.width = static_cast<int>(args.integer("width", 1, 4096, s.layout.width));
  s.layout.hidden_layers = static_cast<int>(args.integer("depth", 1, 64, s.layout.hidden_layers));
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  s.data.seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, static_cast<std::int64_t>(s.data.seed)));
  s.resume = args.has("resume");
  s.keep_dataset = args.has("keep-dataset");
  // oneDNN runs on OpenMP; it reads the thread count when it first starts.
  if (threads > 0) setenv("OMP_NUM_THREADS", std::to_string(threads).c_str(), 1);

  engine::jobs::JobSystem jobs({.threads = threads});
  engine::ecs::World world;
  // The transfer does not depend on the lighting, but the scene is checked
  // as every command checks it: an environment outside the scene's folder,
  // missing or malformed is refused here too.
  const auto loaded = engine::scene::load_gltf(world, scene_path);
  for (const auto& w : loaded.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const auto& assets = world.resource<engine::scene::SceneAssets>();

  std::unique_ptr<engine::core::ProgressBar> sampling, training;
  bake::BakeCallbacks cb;
  cb.sampling = [&](std::size_t done, std::size_t total) {
    if (!sampling) sampling = std::make_unique<engine::core::ProgressBar>("sampling transfer", total);
    sampling->update(done);
    if (done == total) sampling->finish();
  };
  cb.training = [&](int it, int total, float loss) {
    if (!training) training = std::make_unique<engine::core::ProgressBar>("training", static_cast<std::uint64_t>(total));
    char note[64];
    std::snprintf(note, sizeof(note), "  L1 %.5f", loss);
    training->update(static_cast<std::uint64_t>(it), note);
    if (it == total) training->finish(note);
  };
  bake::BakeReport r;
  jobs.run([&] { r = bake::run_bake(assets, out, s, cb); });

  if (args.has("curve")) {
    // Training curve: mean batch L1 per 100 iterations and validation RMSE per 1000.
    const std::string prefix = args.str("curve");
    std::string csv = "iteration,train_l1,validation_rmse\n";
    std::vector<double> it, l1, vit, vrmse;
    for (const auto& [i, l] : r.loss_curve) {
      it.push_back(i);
      l1.push_back(l);
    }
    for (const auto& [i, v] : r.validation_curve) {
      vit.push_back(i);
      vrmse.push_back(v);
    }
    std::size_t vi = 0;
    for (const auto& [i, l] : r.loss_curve) {
      csv += std::to_string(i) + "," + std::to_string(l) + ",";
      if (vi < r.validation_curve.size() && r.validation_curve[vi].first == i) csv += std::to_string(r.validation_curve[vi++].second);
      csv += "\n";
    }
    engine::io::write_file_atomically(prefix + ".csv", std::as_bytes(std::span(csv.data(), csv.size())));
    engine::image::write_svg_plot(prefix + ".svg",
                                  {.title = "Training curve: " + scene_path, .x_label = "iteration", .y_label = "error", .log_y = true},
                                  {{"train L1 (mean per 100 it)", it, l1, "#1f77b4", false},
                                   {"validation RMSE", vit, vrmse, "#d62728", true}});
  }
  std::printf("baked %s -> %s\n", scene_path.c_str(), out.c_str());
  std::printf("  data:     %zu samples (%zu train, %zu validation) from %d points x %d directions, %d rays each, %.1f s%s\n",
              r.samples, r.training_samples, r.validation_samples, s.data.points, s.data.outgoing_per_point,
              s.data.rays, r.data_seconds, r.dataset_from_cache ? " (cached)" : "");
  std::printf("  training: %d iterations of %d in %.1f s (%.0f samples/s)%s, %d rollbacks\n", r.iterations, s.train.batch,
              r.train_seconds, r.train_seconds > 0 ? (r.iterations - r.resumed_from) * double(s.train.batch) / r.train_seconds : 0.0,
              r.resumed_from ? (", resumed at " + std::to_string(r.resumed_from)).c_str() : "", r.rollbacks);
  std::printf("  model:    decoder %.1f KB + latents %.1f KB (%zu welded vertices x %d floats)\n",
              static_cast<double>(r.decoder_bytes) / 1024.0, static_cast<double>(r.latent_bytes) / 1024.0, r.latent_rows, s.latent_dim);
  std::printf("  validation RMSE per SH band l=0..4: %.4f %.4f %.4f %.4f %.4f (all: %.4f)\n", r.validation.rmse[0],
              r.validation.rmse[1], r.validation.rmse[2], r.validation.rmse[3], r.validation.rmse[4], r.validation.total);
  std::printf("  constant predictor:                 %.4f %.4f %.4f %.4f %.4f (all: %.4f)\n", r.constant.rmse[0],
              r.constant.rmse[1], r.constant.rmse[2], r.constant.rmse[3], r.constant.rmse[4], r.constant.total);
  return 0;
}

}  // namespace transgi::cli
