#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/image/metrics.h"
#include "engine/scene/scene_assets.h"
#include "eval/network_variants.h"
#include "eval/pareto.h"
#include "eval/reference_cache.h"
#include "eval/scene_fingerprint.h"
#include "model/model_file.h"

namespace transgi::cli {

namespace {

using namespace engine;

std::vector<int> int_list(const Args& args, const std::string& name, const std::string& fallback) {
  const std::string s = args.str(name, fallback);
  std::vector<int> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      const int v = std::stoi(item, &used);
      if (used != item.size() || v <= 0) throw std::invalid_argument(item);
      out.push_back(v);
    } catch (const std::exception&) {
      throw UsageError("bench-pareto: --" + name + ": expected a comma-separated list of positive integers, got '" + s + "'");
    }
  }
  if (out.empty()) throw UsageError("bench-pareto: --" + name + ": empty list");
  return out;
}

}  // namespace

// transgi bench-pareto: frame time against GI error for TransGI (one factor
// at a time around the default: probe grid, rays, map size, decoder width,
// depth and latent size), DDGI (probe grid), and the path tracer given the
// same time per frame.
int run_bench_pareto(const std::vector<std::string>& argv) {
  const Args args("bench-pareto", argv,
                  {"scene", "model", "out", "width", "height", "spp", "frames", "ddgi-frames", "ddgi-warmup", "timing-frames",
                   "camera", "threads", "cache", "seed", "grids", "rays", "maps", "widths", "depths", "latents", "ddgi-grids",
                   "default-grid", "default-rays", "default-map", "bake-iters", "bake-points", "bake-dirs"},
                  {"no-network", "report-only"});
  const std::string scene_path = args.str("scene"), model_path = args.str("model");
  const std::filesystem::path out = args.str("out");
  const int width = static_cast<int>(args.integer("width", 16, 8192, 160));
  const int height = static_cast<int>(args.integer("height", 16, 8192, 90));
  const int spp = static_cast<int>(args.integer("spp", 1, 1'000'000, 1024));
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));
  const auto seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 0));
  const std::string camera = args.str("camera", std::string());
  const std::filesystem::path cache = args.str("cache", std::string(".transgi-cache"));
  const int frames = static_cast<int>(args.integer("frames", 1, 100000, 96));
  const int ddgi_frames = static_cast<int>(args.integer("ddgi-frames", 1, 100000, 160));
  const int timing = static_cast<int>(args.integer("timing-frames", 1, 1000, 5));
  const std::vector<int> grids = int_list(args, "grids", "4,8,16"), rays = int_list(args, "rays", "50,100,200"),
                         maps = int_list(args, "maps", "50,100,200"), widths = int_list(args, "widths", "64,128,256"),
                         depths = int_list(args, "depths", "3,4,5"), latents = int_list(args, "latents", "7,23"),
                         ddgi_grids = int_list(args, "ddgi-grids", "4,8,16");
  const int default_grid = static_cast<int>(args.integer("default-grid", 1, 64, 8));
  const int default_rays = static_cast<int>(args.integer("default-rays", 1, 100000, 100));
  const int default_map = static_cast<int>(args.integer("default-map", 4, 4096, 100));
  bake::DatasetSettings data;
  data.points = static_cast<int>(args.integer("bake-points", 1, 100'000'000, data.points));
  data.rays = static_cast<int>(args.integer("bake-dirs", 1, 1'000'000, data.rays));
  const int bake_iters = static_cast<int>(args.integer("bake-iters", 1, 100'000'000, 5000));

  if (args.has("report-only")) {
    // Re-render the plot and tables from an earlier run's pareto.csv.
    auto points = eval::read_pareto_csv(out / "pareto.csv");
    eval::mark_pareto_front(points);
    eval::write_pareto_plot(out / "pareto.svg", "GI error against frame time: " + scene_path, points);
    eval::write_ablation_markdown(out / "ablation.md", "# Run time against error: " + scene_path + "\n\n(re-rendered from pareto.csv)\n\n![](pareto.svg)", points);
    std::printf("re-rendered %s/pareto.svg and ablation.md from pareto.csv\n", out.string().c_str());
    return 0;
  }
  auto base_model = model::load_model(model_path);
  eval::LoadedScene ref_scene = eval::load_scene(scene_path, camera, threads);
  const auto& assets = ref_scene.app->world().resource<scene::SceneAssets>();
  model::validate_model(base_model, assets, model_path);
  const auto shared_base = std::make_shared<const model::TransferModel>(std::move(base_model));
  std::filesystem::create_directories(out);
  const eval::ReferenceImages ref = eval::reference_images(ref_scene, width, height, eval::ReferenceOptions{spp, 0.0f, seed}, cache);
  double smallest_seen = 0;  // for the noise note at the end

  std::vector<eval::ParetoPoint> points;
  auto score = [&](eval::ParetoPoint p, const image::ImageRGB& gi) {
    const auto m = image::compare_images(gi, ref.gi);
    p.rmse = m.rmse;
    p.l1 = m.l1;
    p.ssim = m.ssim;
    std::printf("  %-10s %-40s %9.2f ms  RMSE %.4f  SSIM %.3f\n", p.method.c_str(), p.variant.c_str(), p.frame_ms, p.rmse, p.ssim);
    std::fflush(stdout);
    smallest_seen = smallest_seen > 0 ? std::min(smallest_seen, p.rmse) : p.rmse;
    points.push_back(p);
  };

  // --- TransGI: one factor at a time ---------------------------------------
  auto transgi_run = [&](const std::string& variant, const std::string& group, int grid, int ray_count, int map,
                         const std::shared_ptr<const model::TransferModel>& m) {
    eval::TransgiRunOptions t;
    t.frames = frames;
    t.timing_frames = timing;
    t.placement.scene_dims = glm::ivec3(grid);
    t.progress = false;
    t.settings.direct_spp = 0;
    t.settings.seed = seed;
    t.settings.probes.seed = seed + 1;
    t.settings.probes.rays_per_probe = ray_count;
    t.settings.probes.map = probes::MapLayout{map, std::max(2, map / 2)};
    // The cost of a dynamic scene: no probe is allowed to freeze.
    t.settings.probes.skip.skip_converged = false;
    eval::LoadedScene s = eval::load_scene(scene_path, camera, threads);
    const eval::MethodRun r = eval::run_transgi(s, m, width, height, t);
    eval::ParetoPoint p{"TransGI", variant, group, r.frame_ms};
    for (const auto& st : r.stages)
      if (st.name == "network inference") p.inference_ms = st.ms;
    score(p, r.gi);
  };
  std::printf("TransGI (%d frames, the last %d timed, %dx%d):\n", frames, timing, width, height);
  transgi_run("default", "", default_grid, default_rays, default_map, shared_base);
  for (int g : grids)
    if (g != default_grid) transgi_run("probes " + std::to_string(g) + "^3", "probes", g, default_rays, default_map, shared_base);
  for (int r : rays)
    if (r != default_rays) transgi_run("rays " + std::to_string(r), "rays", default_grid, r, default_map, shared_base);
  for (int m : maps)
    if (m != default_map)
      transgi_run("map " + std::to_string(m) + "x" + std::to_string(std::max(2, m / 2)), "map", default_grid, default_rays, m, shared_base);

  // --- Decoder variants, each re-baked (cached) from one dataset ------------
  if (!args.has("no-network")) {
    eval::NetworkVariantBaker baker(assets, eval::scene_fingerprint(ref_scene.app->world()), data, bake_iters, cache);
    std::vector<eval::NetworkVariant> variants;
    const int dl = shared_base->latent_dim, dw = shared_base->decoder.layout().width, dd = shared_base->decoder.layout().hidden_layers;
    auto add = [&](int l, int w, int d) {
      for (const auto& v : variants)
        if (v.latent_dim == l && v.width == w && v.depth == d) return;
      variants.push_back({"latent " + std::to_string(l) + ", width " + std::to_string(w) + ", depth " + std::to_string(d), l, w, d});
    };
    add(dl, dw, dd);
    for (int w : widths) add(dl, w, dd);
    for (int d : depths) add(dl, dw, d);
    for (int l : latents) add(l, dw, dd);
    for (const auto& v : variants) {
      const auto m = baker.get(v);
      transgi_run("network: " + v.name, "network", default_grid, default_rays, default_map, m);
    }
  }

  // --- DDGI ------------------------------------------------------------------
  std::printf("DDGI (%d updates, RTXGI defaults):\n", ddgi_frames);
  for (int g : ddgi_grids) {
    eval::DdgiRunOptions d;
    d.frames = ddgi_frames;
    d.timing_frames = timing;
    d.placement.scene_dims = glm::ivec3(g);
    d.progress = false;
    d.settings.warmup_frames = static_cast<int>(args.integer("ddgi-warmup", 0, 100000, 64));
    d.settings.seed = seed + 1;
    d.render.direct_spp = 0;
    d.render.seed = seed;
    eval::LoadedScene s = eval::load_scene(scene_path, camera, threads);
    const eval::MethodRun r = eval::run_ddgi(s, width, height, d);
    score({"DDGI", "probes " + std::to_string(g) + "^3", "probes", r.frame_ms}, r.gi);
  }

  // --- The path tracer with the same time per frame ---------------------------
  // Its cost per sample per pixel, measured now (not from the cached reference).
  double seconds = 0;
  (void)eval::path_traced_gi(ref_scene, width, height, 4, seed + 7, &seconds);
  const double ms_per_spp = seconds * 1000.0 / 4.0;
  std::printf("path tracer: %.2f ms per sample per pixel at %dx%d; at equal time:\n", ms_per_spp, width, height);
  std::set<int> done;
  const std::vector<eval::ParetoPoint> timed = points;  // score() appends to points
  for (const auto& p : timed) {
    const int n = std::max(1, static_cast<int>(std::lround(p.frame_ms / ms_per_spp)));
    if (!done.insert(n).second) continue;
    double t = 0;
    const image::ImageRGB gi = eval::path_traced_gi(ref_scene, width, height, n, seed + 11, &t);
    eval::ParetoPoint q{"path tracer (equal time)", std::to_string(n) + " spp", "", t * 1000.0};
    q.spp = n;
    score(q, gi);
  }

  eval::mark_pareto_front(points);
  eval::write_pareto_csv(out / "pareto.csv", points);
  eval::write_pareto_plot(out / "pareto.svg", "GI error against frame time: " + scene_path, points);
  std::ostringstream header;
  header << "# Run time against error: " << scene_path << "\n\n" << width << "x" << height << ", GI pass, reference " << ref.spp
         << " spp. TransGI: " << frames << " probe frames (no converged-probe skip), DDGI: " << ddgi_frames
         << " updates; frame times are medians of the last " << timing << " frames.\n\nCommand: `" << command_line("bench-pareto", argv) << "`\n\n![](pareto.svg)";
  eval::write_ablation_markdown(out / "ablation.md", header.str(), points);
  std::printf("Pareto front:");
  for (const auto& p : points)
    if (p.on_front) std::printf(" [%s %s]", p.method.c_str(), p.variant.c_str());
  std::printf("\nwrote %s (pareto.csv, pareto.svg, ablation.md)\n", out.string().c_str());
  std::printf("%s\n", eval::reference_noise_note(ref, smallest_seen).c_str());
  return 0;
}

}  // namespace transgi::cli
