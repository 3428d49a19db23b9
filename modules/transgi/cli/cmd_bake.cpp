#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <span>
#include <string>
#include <thread>

#include "bake/bake_job.h"
#include "model/gemm.h"
#include "cli/args.h"
#include "cli/bake_processes.h"
#include "cli/commands.h"
#include "engine/core/progress.h"
#include "engine/image/svg_plot.h"
#include "engine/io/atomic_file.h"
#include "engine/jobs/job_system.h"
#include "engine/scene/gltf_loader.h"
#include "engine/scene/scene_assets.h"

namespace transgi::cli {

namespace {

// "310 | 305 points/s" (rank 0 first), or "-" before any rate is known.
std::string rates_text(std::span<const double> rates, const char* unit) {
  if (rates.empty()) return "-";
  std::string text;
  for (std::size_t i = 0; i < rates.size(); ++i) {
    char v[32];
    std::snprintf(v, sizeof(v), "%s%.0f", i ? " | " : "", rates[i]);
    text += v;
  }
  return text + " " + unit;
}

// A progress note with every rank's rate; nothing with one rank.
std::string rank_rates_note(std::span<const double> rates, const char* unit) {
  return rates.size() < 2 ? std::string() : "  ranks " + rates_text(rates, unit);
}

struct BakeCommand {
  bake::BakeSettings settings;
  std::string scene, out, curve;
  int threads = 0;  // 0: the machine's cores, shared between its ranks
};

BakeCommand parse_bake_command(const Args& args) {
  BakeCommand c;
  c.scene = args.str("scene");
  c.out = args.str("out");
  if (args.has("curve")) c.curve = args.str("curve");
  bake::BakeSettings& s = c.settings;
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
  c.threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  s.data.seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, static_cast<std::int64_t>(s.data.seed)));
  s.resume = args.has("resume");
  s.keep_dataset = args.has("keep-dataset");
  if (args.choice("latent-updates", {"all", "touched"}, std::string("all")) == "touched")
    s.train.latent_updates = bake::LatentUpdates::Touched;
  s.train.gradient_blocks = static_cast<int>(args.integer("gradient-blocks", 1, 4096, s.train.gradient_blocks));
  if ((s.train.gradient_blocks & (s.train.gradient_blocks - 1)) != 0)
    throw UsageError("bake: --gradient-blocks: expected a power of two, got '" + std::to_string(s.train.gradient_blocks) + "'");

  return c;
}

// Training curve: mean batch L1 per 100 iterations and validation RMSE per 1000.
void write_training_curve(const BakeCommand& c, const bake::BakeReport& r) {
  const std::string& prefix = c.curve;
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
                                {.title = "Training curve: " + c.scene, .x_label = "iteration", .y_label = "error", .log_y = true},
                                {{"train L1 (mean per 100 it)", it, l1, "#1f77b4", false},
                                 {"validation RMSE", vit, vrmse, "#d62728", true}});
}

void print_bake_report(const BakeCommand& c, const bake::BakeReport& r) {
  const bake::BakeSettings& s = c.settings;
  std::printf("baked %s -> %s\n", c.scene.c_str(), c.out.c_str());
  std::printf("  data:     %zu samples (%zu train, %zu validation) from %d points x %d directions, %d rays each, %.1f s%s\n",
              r.samples, r.training_samples, r.validation_samples, s.data.points, s.data.outgoing_per_point,
              s.data.rays, r.data_seconds, r.dataset_from_cache ? " (cached)" : "");
  if (r.ranks > 1)
    std::printf("  ranks:    %d; sampling %s, training %s; exchange %.1f s of %.1f s, %.0f KB sent a step by rank 0\n",
                r.ranks, rates_text(r.sampling_rates, "points/s").c_str(),
                rates_text(r.training_rates, "samples/s").c_str(), r.exchange_seconds, r.train_seconds,
                r.bytes_sent_per_step / 1024.0);
  std::printf("  training: %d iterations of %d in %.1f s (%.0f samples/s)%s, %d rollbacks\n", r.iterations, s.train.batch,
              r.train_seconds, r.train_seconds > 0 ? (r.iterations - r.resumed_from) * double(s.train.batch) / r.train_seconds : 0.0,
              r.resumed_from ? (", resumed at " + std::to_string(r.resumed_from)).c_str() : "", r.rollbacks);
  std::printf("  model:    decoder %.1f KB + latents %.1f KB (%zu welded vertices x %d floats)\n",
              static_cast<double>(r.decoder_bytes) / 1024.0, static_cast<double>(r.latent_bytes) / 1024.0, r.latent_rows, s.latent_dim);
  std::printf("  validation RMSE per SH band l=0..4: %.4f %.4f %.4f %.4f %.4f (all: %.4f)\n", r.validation.rmse[0],
              r.validation.rmse[1], r.validation.rmse[2], r.validation.rmse[3], r.validation.rmse[4], r.validation.total);
  std::printf("  constant predictor:                 %.4f %.4f %.4f %.4f %.4f (all: %.4f)\n", r.constant.rmse[0],
              r.constant.rmse[1], r.constant.rmse[2], r.constant.rmse[3], r.constant.rmse[4], r.constant.total);
}

// This process's part of the bake: all of it alone, or one rank's under
// mpirun or srun (docs/bake.md, "Baking on many machines"), the ranks on one
// machine sharing its cores. Rank 0 alone shows progress and reports.
void bake_as_rank(const BakeCommand& c, const BakeProcesses& processes) {
  bake::Communicator& comm = *processes.comm;
  const bool lead = comm.rank() == 0;
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int rank_threads = c.threads > 0 ? c.threads : std::max(1, cores / std::max(1, processes.ranks_on_this_machine));
  if (c.threads > 0 || comm.size() > 1) model::set_gemm_threads(rank_threads);

  engine::jobs::JobSystem jobs({.threads = c.threads > 0 || comm.size() > 1 ? rank_threads : 0});
  engine::ecs::World world;
  // The transfer does not depend on the lighting, but the scene is checked
  // as every command checks it: an environment outside the scene's folder,
  // missing or malformed is refused here too.
  const auto loaded = engine::scene::load_gltf(world, c.scene);
  if (lead)
    for (const auto& w : loaded.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  const auto& assets = world.resource<engine::scene::SceneAssets>();
  if (lead && comm.size() > 1)
    std::fprintf(stderr, "baking on %d ranks (%s), %d threads each\n", comm.size(), mpi_description().c_str(), rank_threads);

  std::unique_ptr<engine::core::ProgressBar> sampling, training;
  bake::BakeCallbacks cb;
  cb.sampling = [&](std::size_t done, std::size_t total, std::span<const double> rates) {
    if (!sampling) sampling = std::make_unique<engine::core::ProgressBar>("sampling transfer", total);
    const std::string note = rank_rates_note(rates, "points/s");
    sampling->update(done, note);
    if (done == total) sampling->finish(note);
  };
  cb.training = [&](int it, int total, float loss, std::span<const double> rates) {
    if (!training) {
      if (it > 1) std::fprintf(stderr, "resuming from the checkpoint at iteration %d\n", it - 1);
      training = std::make_unique<engine::core::ProgressBar>("training", static_cast<std::uint64_t>(total));
    }
    char l1[32];
    std::snprintf(l1, sizeof(l1), "  L1 %.5f", loss);
    const std::string note = l1 + rank_rates_note(rates, "samples/s");
    training->update(static_cast<std::uint64_t>(it), note);
    if (it == total) training->finish(note);
  };
  bake::BakeReport r;
  jobs.run([&] { r = bake::run_bake(assets, c.out, c.settings, cb, comm); });
  if (!lead) return;
  if (!c.curve.empty()) write_training_curve(c, r);
  print_bake_report(c, r);
}

}  // namespace

int run_bake(const std::vector<std::string>& argv) {
  const Args args("bake", argv,
                  {"scene", "out", "points", "dirs", "outgoing", "iters", "batch", "lr", "latent-dim", "width", "depth",
                   "threads", "seed", "curve", "max-points-per-vertex", "latent-updates",
                   "gradient-blocks"},
                  {"resume", "keep-dataset"});
  const BakeCommand command = parse_bake_command(args);
  const BakeProcesses processes = join_bake_processes();
  try {
    bake_as_rank(command, processes);
  } catch (const std::exception& e) {
    if (processes.comm->size() <= 1) throw;
    // The other ranks may wait in an exchange this rank will never join: end the job.
    std::fprintf(stderr, "transgi bake: rank %d of %d: %s\n", processes.comm->rank(), processes.comm->size(), e.what());
    std::fflush(stderr);
    abort_bake_processes(processes, 1);
    throw;
  }
  return 0;
}

}  // namespace transgi::cli
