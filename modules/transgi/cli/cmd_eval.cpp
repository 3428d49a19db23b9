#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "cli/args.h"
#include "cli/runtime_options.h"
#include "cli/commands.h"
#include "engine/image/exr.h"
#include "engine/image/png.h"
#include "engine/image/tonemap.h"
#include "engine/scene/scene_assets.h"
#include "eval/decomposition.h"
#include "eval/eval_report.h"
#include "eval/reference_cache.h"
#include "model/model_file.h"

namespace transgi::cli {

namespace {

using namespace engine;

image::ImageRGB plus(const image::ImageRGB& a, const image::ImageRGB& b) {
  image::ImageRGB r = a;
  for (std::size_t i = 0; i < r.pixels.size(); ++i) r.pixels[i] += b.pixels[i];
  return r;
}

void write_image(const std::filesystem::path& dir, const std::string& name, const image::ImageRGB& img) {
  image::write_exr(dir / (name + ".exr"), img);
  image::write_png_srgb(dir / (name + ".png"), img);
}

}  // namespace

// transgi eval: the reference, TransGI and DDGI on one scene, in two setups
// (GI only; GI + the reference's direct light), with images, error maps and
// the paper's tables.
int run_eval(const std::vector<std::string>& argv) {
  const Args args("eval", argv,
                  {"scene", "model", "out", "width", "height", "spp", "frames", "ddgi-frames", "ddgi-warmup", "probe-grid",
                   "gbuffer-spp", "camera", "threads", "cache", "seed", "reference-error", "temporal", "probe-volume", "cascades",
                   "cascade-cell", "cascade-look-ahead", "cascade-fit-scene", "cascade-map-width", "reflections", "near-field-rays", "near-field-reach",
                   "near-field-filter", "near-field-budget", "near-field-history", "near-field-cut-fade", "map-width"},
                  {"decompose", "allow-unbaked"});
  const std::string scene_path = args.str("scene"), model_path = args.str("model");
  const std::filesystem::path out = args.str("out");
  const int width = static_cast<int>(args.integer("width", 16, 8192, 320));
  const int height = static_cast<int>(args.integer("height", 16, 8192, 180));
  const int spp = static_cast<int>(args.integer("spp", 2, 1'000'000, 1024));
  const float reference_error = static_cast<float>(args.number("reference-error", 0.0, 1.0, 0.0));
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  const auto seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  const std::string camera = args.str("camera", std::string());
  const std::filesystem::path cache = args.str("cache", std::string(".transgi-cache"));

  eval::TransgiRunOptions t;
  t.frames = static_cast<int>(args.integer("frames", 1, 100000, 160));
  t.placement = probe_placement_from(args, runtime::ProbeVolumeMode::Cascades);
  t.settings.gbuffer_spp = static_cast<int>(args.integer("gbuffer-spp", 1, 64, 1));
  t.settings.direct_spp = 0;  // both setups take direct light from the reference
  t.settings.seed = seed;
  t.settings.probes.seed = seed + 1;
  near_field_from(args, t.settings.near_field);
  t.settings.probes.map.width = static_cast<int>(args.integer("map-width", 4, 4096, t.settings.probes.map.width));
  t.settings.probes.map.height = std::max(2, t.settings.probes.map.width / 2);
  // Both methods alike: the GI image of the last N frames averaged, each with
  // its own jittered G-buffer sample (a still view's temporal antialiasing).
  const int temporal = static_cast<int>(args.integer("temporal", 1, 1024, runtime::quality_preset().temporal_window));
  t.settings.temporal_window = temporal;
  t.timing_frames = std::max(t.timing_frames, temporal);
  eval::DdgiRunOptions d;
  d.frames = static_cast<int>(args.integer("ddgi-frames", 1, 100000, 200));
  d.settings.warmup_frames = static_cast<int>(args.integer("ddgi-warmup", 0, 100000, 64));
  d.placement = t.placement;
  d.render.gbuffer_spp = t.settings.gbuffer_spp;
  d.render.direct_spp = 0;
  d.render.seed = seed;
  d.render.temporal_window = temporal;
  d.timing_frames = std::max(d.timing_frames, temporal);
  d.settings.seed = seed + 1;

  // Fail on a bad model before minutes of reference rendering.
  auto model = model::load_model(model_path);
  eval::LoadedScene reference_scene = eval::load_scene(scene_path, camera, threads);
  model::validate_model(model, reference_scene.app->world().resource<scene::SceneAssets>(), model_path, args.has("allow-unbaked"));
  std::filesystem::create_directories(out / "images");
  std::filesystem::create_directories(out / "heat");

  const eval::ReferenceImages ref =
      eval::reference_images(reference_scene, width, height, eval::ReferenceOptions{spp, reference_error, seed}, cache);
  std::printf("reference: %s (%.0f spp on average, %.1f s)%s\n", ref.key.c_str(), ref.mean_spp, ref.seconds,
              ref.from_cache ? ", from the cache" : "");

  eval::EvalReport report;
  report.scene = scene_path;
  report.command = command_line("eval", argv);
  report.width = width;
  report.height = height;
  report.reference_spp = ref.spp;
  report.reference_seconds = ref.seconds;
  report.reference_cached = ref.from_cache;
  report.reference_key = ref.key;
  report.reference_mean_spp = ref.mean_spp;
  report.reference_target_error = ref.target_error;
  report.reference_noise_gi = ref.noise_gi;
  report.reference_noise_full = ref.noise_full;
  {
    const auto& assets = reference_scene.app->world().resource<scene::SceneAssets>();
    for (const auto& m : assets.meshes) report.vertices += m->positions.size();
    for (const auto& m : model.meshes) report.latent_rows += m.latents.rows();
    report.decoder_bytes = model.decoder_bytes();
    report.latent_bytes = model.latent_bytes();
    report.latent_dim = model.latent_dim;
    report.bake_settings = model.bake_settings_json;
  }
  const auto shared_model = std::make_shared<const model::TransferModel>(std::move(model));

  std::vector<eval::DecompositionRow> decomposition;
  {
    eval::LoadedScene s = eval::load_scene(scene_path, camera, threads);
    eval::MethodResult m{"TransGI", "transgi", "", eval::run_transgi(s, shared_model, width, height, t), {}, {}};
    m.settings = std::to_string(t.frames) + " probe frames, " + std::to_string(t.settings.probes.rays_per_probe) + " rays per probe, " +
                 std::to_string(t.settings.probes.map.width) + "x" + std::to_string(t.settings.probes.map.height) + " maps";
    report.methods.push_back(std::move(m));
    if (args.has("decompose")) decomposition = eval::decompose_transgi(s, ref.gi, width, height, eval::DecompositionOptions{});
  }
  {
    eval::LoadedScene s = eval::load_scene(scene_path, camera, threads);
    eval::MethodResult m{"DDGI", "ddgi", "", eval::run_ddgi(s, width, height, d), {}, {}};
    m.settings = std::to_string(d.frames) + " updates (first " + std::to_string(d.settings.warmup_frames) +
                 " with a cold-start ramp), RTXGI defaults: " + std::to_string(d.settings.rays_per_probe) + " rays, hysteresis 0.97";
    report.methods.push_back(std::move(m));
  }

  write_image(out / "images", "reference_gi", ref.gi);
  write_image(out / "images", "reference_full", ref.full);
  write_image(out / "images", "reference_direct", ref.direct);
  for (const char* setup : {"gi", "full"}) {
    const bool gi = std::string(setup) == "gi";
    const image::ImageRGB& target = gi ? ref.gi : ref.full;
    // One error scale per setup for every method, so the maps compare.
    double scale = 0;
    for (auto& m : report.methods) {
      const image::ImageRGB img = gi ? m.run.gi : plus(m.run.gi, ref.direct);
      (gi ? m.gi : m.gi_di) = image::compare_images(img, target);
      double used = 0;
      (void)image::error_heatmap(img, target, 0, &used);
      scale = std::max(scale, used);
    }
    for (auto& m : report.methods) {
      const image::ImageRGB img = gi ? m.run.gi : plus(m.run.gi, ref.direct);
      write_image(out / "images", m.slug + "_" + setup, img);
      image::write_png(out / "heat" / (m.slug + "_" + setup + ".png"), image::error_heatmap(img, target, scale));
    }
  }
  double smallest = 0;
  for (const auto& m : report.methods) smallest = smallest > 0 ? std::min(smallest, m.gi.rmse) : m.gi.rmse;
  report.reference_note = eval::reference_noise_note(ref, smallest);
  eval::write_results_json(out / "results.json", report);
  eval::write_results_markdown(out / "results.md", report);
  eval::write_index_html(out / "index.html", report);
  for (const auto& m : report.methods)
    std::printf("%-8s GI: RMSE %.4f L1 %.4f SSIM %.3f mean x%.3f | GI+DI: RMSE %.4f L1 %.4f SSIM %.3f | frame %.2f ms\n", m.name.c_str(),
                m.gi.rmse, m.gi.l1, m.gi.ssim, m.gi.mean_ratio, m.gi_di.rmse, m.gi_di.l1, m.gi_di.ssim, m.run.frame_ms);
  if (!decomposition.empty()) eval::write_decomposition(out, decomposition, ref.gi, ref.noise_gi, report.command);
  std::printf("%s\n", report.reference_note.c_str());
  std::printf("wrote %s (index.html, results.md, results.json, images/, heat/)\n", out.string().c_str());
  return 0;
}

}  // namespace transgi::cli
