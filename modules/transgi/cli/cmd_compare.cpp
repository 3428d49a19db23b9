#include <cstdio>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/image/exr.h"
#include "engine/image/metrics.h"

namespace transgi::cli {

int run_compare(const std::vector<std::string>& argv) {
  const Args args("compare", argv, {"heatmap", "heatmap-max", "top-error", "edge-band-of", "band"}, {"colour"});
  if (args.positional().size() != 2) throw UsageError("compare: expected two EXR files: A.exr B.exr (B is the reference)");
  const auto a = engine::image::read_exr(args.positional()[0]);
  const auto b = engine::image::read_exr(args.positional()[1]);
  if (a.width != b.width || a.height != b.height)
    throw std::runtime_error("image sizes differ: " + args.positional()[0] + " is " + std::to_string(a.width) + "x" +
                             std::to_string(a.height) + ", " + args.positional()[1] + " is " + std::to_string(b.width) +
                             "x" + std::to_string(b.height));
  const auto m = engine::image::compare_images(a, b);
  if (args.has("heatmap")) {
    double used = 0;
    const auto heat = engine::image::error_heatmap(a, b, args.number("heatmap-max", 0, 1e9, 0.0), &used);
    engine::image::write_png(args.str("heatmap"), heat);
    std::fprintf(stderr, "heat map: black = 0, white = %.4g mean absolute error (clamped linear RGB)\n", used);
  }
  if (args.has("edge-band-of")) {
    // The error near the edges of another image (a reference's direct pass:
    // its shadow edges), printed on a line of its own.
    const auto guide = engine::image::read_exr(args.str("edge-band-of"));
    if (guide.width != a.width || guide.height != a.height)
      throw std::runtime_error("--edge-band-of: " + args.str("edge-band-of") + " is not " + std::to_string(a.width) + "x" +
                               std::to_string(a.height));
    const auto band = engine::image::edge_band(guide, static_cast<int>(args.integer("band", 0, 64, 3)));
    std::size_t n = 0;
    for (auto v : band) n += v;
    std::printf("{\"edge_band_rmse\": %.8g, \"edge_band_pixels\": %zu}\n", engine::image::rmse_clamped_in(a, b, band), n);
  }
  if (args.has("colour")) {
    // Hue and texture against the reference (engine/image/metrics.h), a line of their own.
    const auto c = engine::image::compare_colour(a, b);
    std::printf("{\"chroma_error\": %.6g, \"detail\": %.6g, \"detail_reference\": %.6g, \"detail_ratio\": %.4f, \"colour_pixels\": %zu, "
                "\"speckles\": %.6g, \"speckles_reference\": %.6g}\n",
                c.chroma_error, c.detail_a, c.detail_b, c.detail_b > 0 ? c.detail_a / c.detail_b : 0.0, c.pixels,
                engine::image::speckle_fraction(a), engine::image::speckle_fraction(b));
  }
  if (args.has("top-error")) {
    const double f = args.number("top-error", 0.0, 100.0) / 100.0;
    std::printf("{\"rmse\": %.8g, \"l1\": %.8g, \"ssim\": %.8g, \"relmse\": %.8g, \"mean_ratio\": %.6g, \"top_error_share\": %.6g}\n",
                m.rmse, m.l1, m.ssim, m.relmse, m.mean_ratio, engine::image::top_error_share(a, b, f));
  } else {
    std::printf("{\"rmse\": %.8g, \"l1\": %.8g, \"ssim\": %.8g, \"relmse\": %.8g, \"mean_ratio\": %.6g, \"mean_ratio_rgb\": [%.4f, %.4f, %.4f]}\n",
                m.rmse, m.l1, m.ssim, m.relmse, m.mean_ratio, m.mean_ratio_rgb.r, m.mean_ratio_rgb.g, m.mean_ratio_rgb.b);
  }
  return 0;
}

}  // namespace transgi::cli
