// transgi fly-through: the camera flies a polyline through a level with the
// real-time plugin running (issue 16). Every frame is checked: no GI pixel
// may be non-finite, and the GI pass over the surfaces the camera sees may
// not be black; pixels whose GI is exactly zero are counted too (open ground
// far from anything gets next to no indirect light, so some are right). The
// probes traced per frame are counted against the budget; at the stops, the
// GI image is compared with the path tracer's GI pass of that view.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <glm/gtc/quaternion.hpp>

#include "cli/args.h"
#include "cli/option_specs.h"
#include "cli/commands.h"
#include "cli/reference_view.h"
#include "cli/runtime_options.h"
#include "engine/core/progress.h"
#include "engine/image/exr.h"
#include "engine/image/metrics.h"
#include "engine/jobs/parallel_for.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_plugin.h"
#include "engine/render/path_tracer.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/transform/transform.h"
#include "eval/method_runs.h"
#include "model/model_file.h"
#include "runtime/probe_placement.h"
#include "runtime/transgi_plugin.h"

namespace transgi::cli {

namespace {

using namespace engine;

std::vector<glm::vec3> parse_path(const std::string& text) {
  std::vector<glm::vec3> points;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ';')) {
    glm::vec3 p;
    char c1 = 0, c2 = 0;
    std::stringstream is(item);
    if (!(is >> p.x >> c1 >> p.y >> c2 >> p.z) || c1 != ',' || c2 != ',' || !std::isfinite(p.x) || !std::isfinite(p.y) ||
        !std::isfinite(p.z))
      throw UsageError("--path: '" + item + "' is not x,y,z (finite numbers)");
    points.push_back(p);
  }
  if (points.size() < 2) throw UsageError("--path: give at least two points, x,y,z;x,y,z");
  return points;
}

// The point at arc-length fraction t in [0, 1] of the polyline, and its direction.
std::pair<glm::vec3, glm::vec3> along(const std::vector<glm::vec3>& path, float t) {
  float total = 0;
  for (std::size_t i = 1; i < path.size(); ++i) total += glm::length(path[i] - path[i - 1]);
  float want = std::clamp(t, 0.0f, 1.0f) * total;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const float len = glm::length(path[i] - path[i - 1]);
    if (want <= len || i + 1 == path.size()) {
      const glm::vec3 dir = len > 0 ? (path[i] - path[i - 1]) / len : glm::vec3(0, 0, -1);
      return {path[i - 1] + dir * std::min(want, len), dir};
    }
    want -= len;
  }
  return {path.back(), glm::vec3(0, 0, -1)};
}

}  // namespace

int run_fly_through(const std::vector<std::string>& argv) {
  const Args args("fly-through", argv, fly_through_option_specs(), kFlyThroughSynopsis);
  const std::string scene_path = args.str("scene"), model_path = args.str("model");
  const std::filesystem::path out = args.str("out");
  const int width = static_cast<int>(args.integer("width", 16, 8192, 320));
  const int height = static_cast<int>(args.integer("height", 16, 8192, 180));
  const int frames = static_cast<int>(args.integer("frames", 2, 100000, 300));
  const int reference_spp = static_cast<int>(args.integer("reference-spp", 0, 1 << 20, 256));
  const auto pitch = static_cast<float>(args.number("pitch", -89.0, 89.0, -10.0));
  const std::vector<glm::vec3> path = parse_path(args.str("path"));
  std::vector<int> stops;
  {
    std::stringstream ss(args.str("stops", std::to_string(frames / 3) + "," + std::to_string(2 * frames / 3) + "," + std::to_string(frames)));
    std::string item;
    while (std::getline(ss, item, ',')) {
      const int s = std::atoi(item.c_str());
      if (s < 1 || s > frames) throw UsageError("--stops: each stop is a frame in [1, --frames], got '" + item + "'");
      stops.push_back(s);
    }
  }

  eval::LoadedScene scene = eval::load_scene(scene_path, std::string(), static_cast<int>(args.integer("threads", 0, 1024, 0)));
  ecs::World& world = scene.app->world();
  auto model = model::load_model(model_path);
  model::validate_model(model, world.resource<scene::SceneAssets>(), model_path, args.has("allow-unbaked"));
  const runtime::TransGISettings settings = runtime_settings_from(args, "realtime");
  scene.app->add_plugin<runtime::TransGIPlugin>(settings);
  runtime::attach_latent_meshes(world, std::make_shared<const model::TransferModel>(std::move(model)));
  const runtime::ProbePlacement placement = probe_placement_from(args, runtime::ProbeVolumeMode::Cascades);
  runtime::spawn_probes(world, placement);
  auto& frame = world.resource<runtime::GiFrame>();
  frame.camera = scene.camera;
  frame.width = width;
  frame.height = height;
  std::filesystem::create_directories(out);
  // The budget a frame may spend: each cascade's share (cascade_field_settings).
  int budget = 0;
  for (int k = 0; k < placement.cascades.count; ++k)
    budget += settings.probes.update_budget > 0 ? std::max(1, settings.probes.update_budget >> k) : 0;

  std::ostringstream csv;
  csv << "frame,x,y,z,mean_gi,black_pixels,nonfinite_pixels,probes_traced,probes_entered\n";
  core::ProgressBar bar("fly-through", static_cast<std::uint64_t>(frames), true);
  int worst_black = 0, worst_nonfinite = 0, over_budget = 0, max_traced = 0, black_frames = 0;
  std::vector<int> traced_all;
  std::ostringstream table;
  for (int f = 1; f <= frames; ++f) {
    const auto [eye, dir] = along(path, static_cast<float>(f - 1) / static_cast<float>(frames - 1));
    transform::Transform t = transform::Transform::from_translation(eye);
    const glm::vec3 flat = glm::normalize(glm::vec3(dir.x, 0.0f, dir.z) + glm::vec3(1e-6f, 0, 0));
    const glm::vec3 look = glm::normalize(flat * std::cos(glm::radians(pitch)) + glm::vec3(0, std::sin(glm::radians(pitch)), 0));
    t.rotation = glm::quatLookAtRH(look, glm::vec3(0, 1, 0));
    world.get_mut<transform::Transform>(scene.camera) = t;
    scene.app->jobs().run([&] { scene.app->update(); });
    // Which pixels see a surface: one primary ray per pixel centre.
    const render::CameraRays rays(world.get<scene::Camera>(scene.camera), world.get<transform::WorldTransform>(scene.camera), width, height);
    const auto& rt = world.resource<rt::RtScene>();
    std::vector<std::uint8_t> hit(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
    scene.app->jobs().run([&] {
      jobs::parallel_for(0, height, 4, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
          for (int x = 0; x < width; ++x) {
            rt::Hit h;
            hit[static_cast<std::size_t>(y) * width + x] = rt.intersect(rays.generate_filtered(x, y, glm::vec2(0.5f), 0.0f), h) ? 1 : 0;
          }
      });
    });
    int black = 0, nonfinite = 0, seen = 0;
    double mean = 0, seen_sum = 0;
    for (std::size_t i = 0; i < frame.gi.pixels.size(); ++i) {
      const glm::vec3& p = frame.gi.pixels[i];
      if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b)) ++nonfinite;
      else if (hit[i] && p.r <= 0.0f && p.g <= 0.0f && p.b <= 0.0f) ++black;
      else mean += 0.2126 * p.r + 0.7152 * p.g + 0.0722 * p.b;
      if (hit[i] && std::isfinite(p.r + p.g + p.b)) {
        ++seen;
        seen_sum += p.r + p.g + p.b;
      }
    }
    if (seen > 0 && !(seen_sum > 0)) ++black_frames;
    mean /= static_cast<double>(frame.gi.pixels.size());
    worst_black = std::max(worst_black, black);
    worst_nonfinite = std::max(worst_nonfinite, nonfinite);
    const int traced = frame.probe_stats.traced;
    traced_all.push_back(traced);
    max_traced = std::max(max_traced, f > 1 ? traced : 0);  // frame 1 classifies every probe
    if (f > 1 && budget > 0 && traced > budget) ++over_budget;
    csv << f << ',' << eye.x << ',' << eye.y << ',' << eye.z << ',' << mean << ',' << black << ',' << nonfinite << ',' << traced << ','
        << frame.cascade_probes_entered << '\n';
    if (std::find(stops.begin(), stops.end(), f) != stops.end()) {
      char name[64];
      std::snprintf(name, sizeof(name), "gi_%03d.exr", f);
      image::write_exr(out / name, frame.gi);
      double rmse = -1, ratio = -1;
      if (reference_spp > 0) {
        const image::ImageRGB ref = reference_gi_now(scene, width, height, reference_spp);
        std::snprintf(name, sizeof(name), "reference_gi_%03d.exr", f);
        image::write_exr(out / name, ref);
        const image::ErrorMetrics m = image::compare_images(frame.gi, ref);
        rmse = m.rmse;
        ratio = m.mean_ratio;
      }
      char row[200];
      std::snprintf(row, sizeof(row), "| %d | (%.1f, %.1f, %.1f) | %.4f | %.3f | %d |\n", f, static_cast<double>(eye.x),
                    static_cast<double>(eye.y), static_cast<double>(eye.z), rmse, ratio, traced);
      table << row;
    }
    bar.update(static_cast<std::uint64_t>(f));
  }
  bar.finish();
  {
    const std::filesystem::path p = out / "fly_through.csv", tmp = p.string() + ".tmp";
    std::ofstream(tmp) << csv.str();
    std::filesystem::rename(tmp, p);
  }
  std::sort(traced_all.begin(), traced_all.end());
  std::printf("fly-through: %d frames, %dx%d, %zu path points; per-frame budget %d probes (%s)\n", frames, width, height,
              path.size(), budget, runtime::name_of(placement.mode).data());
  std::printf("frames whose GI pass is black over the surfaces seen: %d; worst frame: %d non-finite GI pixels, %d of %d pixels "
              "with zero GI where a surface is seen\n",
              black_frames, worst_nonfinite, worst_black, width * height);
  std::printf("probes traced per frame: median %d, max %d after the first frame; %d frames over the budget\n",
              traced_all[traced_all.size() / 2], max_traced, over_budget);
  std::printf("| stop (frame) | camera | GI RMSE (%d spp) | mean GI / reference | probes traced |\n| --- | --- | --- | --- | --- |\n%s",
              reference_spp, table.str().c_str());
  std::printf("per-frame log: %s\n", (out / "fly_through.csv").string().c_str());
  return black_frames == 0 && worst_nonfinite == 0 && over_budget == 0 ? 0 : 1;
}

}  // namespace transgi::cli
