// transgi sun-sweep: a sun that moves (issue 16). The real-time TransGI
// plugin runs without a break while the scene's directional light steps
// through `--positions` places on a path across the sky; after each step it
// counts the frames until the GI image's mean stays within 5 % of the value
// it settles at, and compares the settled image with the path tracer's GI
// pass of the scene as it then stands.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/args.h"
#include "cli/option_specs.h"
#include "cli/commands.h"
#include "cli/reference_view.h"
#include "cli/runtime_options.h"
#include "engine/core/progress.h"
#include "engine/image/exr.h"
#include "engine/image/metrics.h"
#include "engine/image/svg_plot.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/scene/sun.h"
#include "engine/transform/transform.h"
#include "eval/method_runs.h"
#include "model/model_file.h"
#include "runtime/probe_placement.h"
#include "runtime/transgi_plugin.h"

namespace transgi::cli {

namespace {

using namespace engine;

double mean_luminance(const image::ImageRGB& img) {
  double s = 0;
  for (const glm::vec3& p : img.pixels) s += 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b;
  return img.pixels.empty() ? 0.0 : s / static_cast<double>(img.pixels.size());
}

// Frames after the move until the mean stays within `tolerance` of `settled`
// for good (1 = the first frame already did); frames + 1 if it never does.
int frames_to_settle(const std::vector<double>& means, double settled, double tolerance) {
  int last_outside = 0;
  for (std::size_t f = 0; f < means.size(); ++f)
    if (!(std::abs(means[f] - settled) <= tolerance * std::abs(settled))) last_outside = static_cast<int>(f) + 1;
  return last_outside + 1;
}

void write_text(const std::filesystem::path& path, const std::string& text) {
  const std::filesystem::path tmp = path.string() + ".tmp";
  {
    std::ofstream f(tmp);
    f << text;
    if (!f) throw std::runtime_error(tmp.string() + ": write failed");
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace

int run_sun_sweep(const std::vector<std::string>& argv) {
  const Args args("sun-sweep", argv, sun_sweep_option_specs(), kSunSweepSynopsis);
  const std::string scene_path = args.str("scene"), model_path = args.str("model");
  const std::filesystem::path out = args.str("out");
  const int width = static_cast<int>(args.integer("width", 16, 8192, 320));
  const int height = static_cast<int>(args.integer("height", 16, 8192, 180));
  const int positions = static_cast<int>(args.integer("positions", 1, 360, 8));
  const int frames = static_cast<int>(args.integer("frames", 17, 100000, 96));
  const int warmup = static_cast<int>(args.integer("warmup", 0, 100000, 96));
  const int reference_spp = static_cast<int>(args.integer("reference-spp", 0, 1 << 20, 512));
  const double tolerance = args.number("settle-tolerance", 1e-4, 1.0, 0.05);
  const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));

  eval::LoadedScene scene = eval::load_scene(scene_path, args.str("camera", std::string()), threads);
  ecs::World& world = scene.app->world();
  const auto sun = scene::find_sun(world);
  if (!sun) throw std::runtime_error(scene_path + ": sun-sweep needs a directional light (KHR_lights_punctual) to turn");
  const glm::vec2 start = scene::sun_angles(glm::normalize(world.get<transform::Transform>(*sun).rotation * glm::vec3(0, 0, 1)));
  // The path: elevation and azimuth each linear from `from` to `to`; by
  // default the scene's own azimuth, the elevation from 10 to 80 degrees.
  const auto e0 = static_cast<float>(args.number("elevation-from", -90, 90, 10.0));
  const auto e1 = static_cast<float>(args.number("elevation-to", -90, 90, 80.0));
  const auto a0 = static_cast<float>(args.number("azimuth-from", -360, 360, start.y));
  const auto a1 = static_cast<float>(args.number("azimuth-to", -360, 360, start.y));

  auto model = model::load_model(model_path);
  model::validate_model(model, world.resource<scene::SceneAssets>(), model_path, args.has("allow-unbaked"));
  runtime::TransGISettings settings = runtime_settings_from(args, "realtime");
  if (args.choice("probe-skip", {"on", "off"}, "on") == "off") settings.probes.skip.classify = settings.probes.skip.skip_converged = false;
  scene.app->add_plugin<runtime::TransGIPlugin>(settings);
  runtime::attach_latent_meshes(world, std::make_shared<const model::TransferModel>(std::move(model)));
  runtime::spawn_probes(world, probe_placement_from(args, runtime::ProbeVolumeMode::Cascades));
  auto& frame = world.resource<runtime::GiFrame>();
  frame.camera = scene.camera;
  frame.width = width;
  frame.height = height;
  std::filesystem::create_directories(out);

  // Position p of the path (p = 0 is where the warm-up runs, 1..positions are measured).
  const auto place = [&](int p) {
    const float t = positions > 0 ? static_cast<float>(p) / static_cast<float>(positions) : 0.0f;
    return glm::vec2(e0 + (e1 - e0) * t, a0 + (a1 - a0) * t);
  };
  core::ProgressBar bar("sun-sweep", static_cast<std::uint64_t>(warmup + positions * frames), true);
  std::uint64_t done = 0;
  const auto step = [&] {
    scene.app->jobs().run([&] { scene.app->update(); });
    bar.update(++done);
  };
  scene::set_sun(world, place(0).x, place(0).y);
  for (int f = 0; f < warmup; ++f) step();

  std::ostringstream csv, trace;
  csv << "position,elevation_deg,azimuth_deg,frames_to_settle,settled_mean,rmse,mean_ratio,ssim\n";
  trace << "position,frame,mean_gi\n";
  std::vector<double> xs, settle_frames, rmses;
  std::vector<double> trace_x, trace_rel;
  struct Row {
    glm::vec2 sun;
    int settle;
    double settled, rmse, ratio;
  };
  std::vector<Row> rows;
  for (int p = 1; p <= positions; ++p) {
    const glm::vec2 s = place(p);
    scene::set_sun(world, s.x, s.y);
    std::vector<double> means;
    for (int f = 0; f < frames; ++f) {
      step();
      means.push_back(mean_luminance(frame.gi));
    }
    // Settled: the mean of the last 16 frames' means.
    double settled = 0;
    for (int f = frames - 16; f < frames; ++f) settled += means[static_cast<std::size_t>(f)] / 16.0;
    const int settle = frames_to_settle(means, settled, tolerance);
    for (int f = 0; f < frames; ++f) {
      trace << p << ',' << f + 1 << ',' << means[static_cast<std::size_t>(f)] << '\n';
      trace_x.push_back((p - 1) * frames + f + 1);
      trace_rel.push_back(settled > 0 ? means[static_cast<std::size_t>(f)] / settled : 0.0);
    }
    char name[64];
    std::snprintf(name, sizeof(name), "gi_%02d.exr", p);
    image::write_exr(out / name, frame.gi);
    Row row{s, settle, settled, -1, -1};
    double ssim = -1;
    if (reference_spp > 0) {
      const image::ImageRGB ref = reference_gi_now(scene, width, height, reference_spp);
      std::snprintf(name, sizeof(name), "reference_gi_%02d.exr", p);
      image::write_exr(out / name, ref);
      const image::ErrorMetrics m = image::compare_images(frame.gi, ref);
      row.rmse = m.rmse;
      row.ratio = m.mean_ratio;
      ssim = m.ssim;
    }
    rows.push_back(row);
    csv << p << ',' << s.x << ',' << s.y << ',' << settle << ',' << settled << ',' << row.rmse << ',' << row.ratio << ',' << ssim << '\n';
    xs.push_back(p);
    settle_frames.push_back(settle);
    rmses.push_back(row.rmse);
  }
  bar.finish();
  write_text(out / "sun_sweep.csv", csv.str());
  write_text(out / "sun_sweep_trace.csv", trace.str());
  image::write_svg_plot(out / "sun_sweep_settle.svg",
                        {"Frames until GI stays within " + std::to_string(static_cast<int>(std::lround(tolerance * 100))) +
                             " % of its settled mean, after each sun move",
                         "sun position", "frames"},
                        {{"frames to settle", xs, settle_frames, "#1f77b4", true}});
  if (reference_spp > 0)
    image::write_svg_plot(out / "sun_sweep_rmse.svg", {"GI RMSE against the path tracer, settled", "sun position", "RMSE"},
                          {{"GI RMSE", xs, rmses, "#d62728", true}});
  image::write_svg_plot(out / "sun_sweep_trace.svg",
                        {"Mean GI over the sweep, relative to each position's settled mean", "frame", "mean / settled"},
                        {{"mean GI / settled", trace_x, trace_rel, "#2ca02c", false}});

  std::printf("sun sweep: %d positions, %d frames each after %d warm-up frames at (%.1f, %.1f) deg; %dx%d\n", positions, frames,
              warmup, static_cast<double>(place(0).x), static_cast<double>(place(0).y), width, height);
  std::printf("| position | elevation | azimuth | frames to settle (%.0f %%) | GI RMSE | mean GI / reference |\n", tolerance * 100);
  std::printf("| --- | --- | --- | --- | --- | --- |\n");
  for (std::size_t i = 0; i < rows.size(); ++i)
    std::printf("| %zu | %.1f | %.1f | %d | %.4f | %.3f |\n", i + 1, static_cast<double>(rows[i].sun.x),
                static_cast<double>(rows[i].sun.y), rows[i].settle, rows[i].rmse, rows[i].ratio);
  std::printf("written: %s/{sun_sweep.csv, sun_sweep_trace.csv, sun_sweep_settle.svg, sun_sweep_trace.svg%s, gi_NN.exr%s}\n",
              out.string().c_str(), reference_spp > 0 ? ", sun_sweep_rmse.svg" : "", reference_spp > 0 ? ", reference_gi_NN.exr" : "");
  return 0;
}

}  // namespace transgi::cli
