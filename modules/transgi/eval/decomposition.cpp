#include "eval/decomposition.h"

#include <cstdio>
#include <functional>
#include <sstream>

#include "engine/image/exr.h"
#include "engine/image/png.h"
#include "engine/image/tonemap.h"
#include "engine/io/atomic_file.h"
#include "engine/render/light_plugin.h"
#include "runtime/components.h"
#include "runtime/gi_frame.h"
#include "runtime/settings.h"

namespace transgi::eval {

namespace {

using namespace engine;

image::ImageRGB render_frozen(LoadedScene& scene, int width, int height, const std::function<void(runtime::TransGISettings&)>& change) {
  ecs::World& world = scene.app->world();
  runtime::TransGISettings& settings = world.resource<runtime::TransGISettings>();
  const runtime::TransGISettings saved = settings;
  change(settings);
  settings.freeze_probes = true;
  // One frame each: the variants compare as single images (a 16-sample
  // G-buffer row stands for what accumulation buys), not blended into the
  // run's temporal history.
  settings.temporal_window = 1;
  auto& frame = world.resource<runtime::GiFrame>();
  frame.width = width;
  frame.height = height;
  scene.app->jobs().run([&] { scene.app->update(); });
  image::ImageRGB gi = frame.gi;
  settings = saved;
  settings.freeze_probes = true;
  return gi;
}

}  // namespace

std::vector<DecompositionRow> decompose_transgi(LoadedScene& scene, const image::ImageRGB& reference_gi, int width, int height,
                                                const DecompositionOptions& o) {
  ecs::World& world = scene.app->world();
  if (world.resource<runtime::TransGISettings>().gi_path != runtime::GiPath::Quality)
    throw std::runtime_error("decomposition needs the quality GI path (the ground-truth transfer is a quality-path oracle)");
  std::vector<DecompositionRow> rows;
  auto add = [&](std::string name, std::string slug, image::ImageRGB gi) {
    DecompositionRow r{std::move(name), std::move(slug), std::move(gi), {}, 0};
    r.metrics = image::compare_images(r.gi, reference_gi);
    const double base = rows.empty() ? r.metrics.rmse : rows.front().metrics.rmse;
    r.share = base > 0 ? 1.0 - (r.metrics.rmse * r.metrics.rmse) / (base * base) : 0.0;
    std::printf("  %-58s GI RMSE %.4f  SSIM %.3f  share of the squared error %+.1f %%\n", r.name.c_str(), r.metrics.rmse, r.metrics.ssim,
                100 * r.share);
    std::fflush(stdout);
    rows.push_back(std::move(r));
  };
  const auto keep = [](runtime::TransGISettings&) {};
  const auto gt = [&](runtime::TransGISettings& s) {
    s.transfer = shading::TransferSource::GroundTruth;
    s.ground_truth_rays = o.ground_truth_rays;
  };
  const auto spp = [&](runtime::TransGISettings& s) { s.gbuffer_spp = o.gbuffer_spp; };
  std::printf("error decomposition (each row: one part replaced by its oracle)\n");
  add("TransGI (the run's probes, network, 1 G-buffer sample)", "base", render_frozen(scene, width, height, keep));
  add("mirror path off (SH-4 transfer on mirrors, as the paper)", "no_mirror",
      render_frozen(scene, width, height, [](runtime::TransGISettings& s) { s.mirror.max_roughness = -1; }));
  add("near-field rays off (probes alone, as the paper)", "no_near_field",
      render_frozen(scene, width, height, [](runtime::TransGISettings& s) { s.near_field.rays = 0; }));
  add("network -> ground-truth transfer", "gt_transfer", render_frozen(scene, width, height, gt));
  add("G-buffer 1 -> " + std::to_string(o.gbuffer_spp) + " samples per pixel", "gbuffer_spp", render_frozen(scene, width, height, spp));

  const render::LightSet& lights = world.resource<render::SceneLights>().set;
  const auto& rt = world.resource<rt::RtScene>();
  // Every field shading reads: authored or scene volumes and the cascades'
  // fields (the default placement), which this row once left out, so that it
  // measured nothing.
  const auto oracle = [&](probes::ProbeField& f) {
    scene.app->jobs().run([&] { f.replace_with_oracle(rt, lights, o.oracle_rays_per_texel, 0x0AC1E); });
  };
  world.view<runtime::ProbeVolume>().each([&](runtime::ProbeVolume& v) {
    if (v.field) oracle(*v.field);
  });
  world.view<runtime::ProbeCascades>().each([&](runtime::ProbeCascades& c) {
    for (const auto& f : c.state.fields)
      if (f) oracle(*f);
  });
  add("probes -> path-traced oracle probes", "oracle_probes", render_frozen(scene, width, height, keep));
  add("both oracles (left: SH-4 truncation, interpolation, G-buffer)", "both_oracles", render_frozen(scene, width, height, gt));
  add("both oracles and " + std::to_string(o.gbuffer_spp) + " G-buffer samples (left: SH-4 and interpolation)", "all_oracles",
      render_frozen(scene, width, height, [&](runtime::TransGISettings& s) {
        gt(s);
        spp(s);
      }));
  return rows;
}

void write_decomposition(const std::filesystem::path& dir, const std::vector<DecompositionRow>& rows, const image::ImageRGB& reference_gi,
                         double reference_noise, const std::string& command) {
  std::filesystem::create_directories(dir / "heat");
  std::filesystem::create_directories(dir / "images");
  double scale = 0;
  for (const auto& r : rows) {
    double used = 0;
    (void)image::error_heatmap(r.gi, reference_gi, 0, &used);
    scale = std::max(scale, used);
  }
  std::ostringstream o;
  o << "# Error decomposition\n\nCommand: `" << command << "`\n\nThe run's probe state, frozen, rendered again with one part "
    << "replaced by its oracle. Share = the fraction of the first row's squared GI error (RMSE^2) that the replacement removes; "
    << "negative = the error grew. The reference's own noise (two independent halves): RMSE " << reference_noise << ".\n\n"
    << "| replaced | GI RMSE | SSIM | share of the squared error | error map |\n| --- | --- | --- | --- | --- |\n";
  for (const auto& r : rows) {
    image::write_png(dir / "heat" / ("decompose_" + r.slug + ".png"), image::error_heatmap(r.gi, reference_gi, scale));
    image::write_exr(dir / "images" / ("decompose_" + r.slug + ".exr"), r.gi);
    char line[512];
    std::snprintf(line, sizeof line, "| %s | %.4f | %.3f | %+.1f %% | ![](heat/decompose_%s.png) |\n", r.name.c_str(), r.metrics.rmse,
                  r.metrics.ssim, 100 * r.share, r.slug.c_str());
    o << line;
  }
  const std::string text = o.str();
  io::write_file_atomically(dir / "decomposition.md", std::as_bytes(std::span(text.data(), text.size())));
}

}  // namespace transgi::eval
