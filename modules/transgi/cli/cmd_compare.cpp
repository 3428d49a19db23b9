#include <cstdio>
#include <optional>

#include <nlohmann/json.hpp>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/image/exr.h"
#include "engine/image/metrics.h"

namespace transgi::cli {

namespace {

// One JSON object a line, through nlohmann-json (a NaN metric prints as null).
void print_json(const nlohmann::ordered_json& j) { std::printf("%s\n", j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace).c_str()); }

}  // namespace

int run_compare(const std::vector<std::string>& argv) {
  const Args args("compare", argv, {"heatmap", "heatmap-max", "top-error", "edge-band-of", "band", "downsample", "colour-mask", "albedo"}, {"colour"});
  if (args.positional().size() != 2) throw UsageError("compare: expected two EXR files: A.exr B.exr (B is the reference)");
  // --downsample N: every metric over N x N block means of both images, where
  // a path-traced reference's per-pixel noise has averaged out.
  const int block = static_cast<int>(args.integer("downsample", 1, 64, 1));
  const auto read = [&](const std::string& path) {
    const auto img = engine::image::read_exr(path);
    return block > 1 ? engine::image::box_downsample(img, block) : img;
  };
  const auto a = read(args.positional()[0]);
  const auto b = read(args.positional()[1]);
  if (a.width != b.width || a.height != b.height)
    throw std::runtime_error("image sizes differ: " + args.positional()[0] + " is " + std::to_string(a.width) + "x" +
                             std::to_string(a.height) + ", " + args.positional()[1] + " is " + std::to_string(b.width) +
                             "x" + std::to_string(b.height));
  // An image an option names, read as A and B are; it must be A's size.
  const auto read_option = [&](const std::string& option) {
    auto img = read(args.str(option));
    if (img.width != a.width || img.height != a.height)
      throw std::runtime_error("--" + option + ": " + args.str(option) + " is not " + std::to_string(a.width) + "x" +
                               std::to_string(a.height));
    return img;
  };
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
    const auto guide = read_option("edge-band-of");
    const auto band = engine::image::edge_band(guide, static_cast<int>(args.integer("band", 0, 64, 3)));
    std::size_t n = 0;
    for (auto v : band) n += v;
    print_json({{"edge_band_rmse", engine::image::rmse_clamped_in(a, b, band)}, {"edge_band_pixels", n}});
  }
  if (args.has("colour")) {
    // Hue and texture against the reference (engine/image/metrics.h), a line of their own.
    // --colour-mask M: only where M (the reference's textured pass) says the
    // surfaces are textured or coloured, downsampled as the images are.
    std::optional<engine::image::ImageRGB> mask, albedo;
    if (args.has("colour-mask")) mask = read_option("colour-mask");
    // --albedo L: the texture's gain against the reference (metrics.h).
    if (args.has("albedo")) albedo = read_option("albedo");
    const auto c = engine::image::compare_colour(a, b, mask ? &*mask : nullptr, albedo ? &*albedo : nullptr);
    nlohmann::ordered_json colour{{"chroma_error", c.chroma_error},
                                  {"detail", c.detail_a},
                                  {"detail_reference", c.detail_b},
                                  {"detail_ratio", c.detail_b > 0 ? c.detail_a / c.detail_b : 0.0},
                                  {"colour_pixels", c.pixels},
                                  {"speckles", engine::image::speckle_fraction(a)},
                                  {"speckles_reference", engine::image::speckle_fraction(b)}};
    if (albedo) {
      colour["texture_gain"] = c.texture_gain;
      colour["texture_correlation"] = c.texture_correlation;
    }
    print_json(colour);
  }
  nlohmann::ordered_json line{{"rmse", m.rmse}, {"l1", m.l1}, {"ssim", m.ssim}, {"relmse", m.relmse}, {"mean_ratio", m.mean_ratio}};
  if (args.has("top-error"))
    line["top_error_share"] = engine::image::top_error_share(a, b, args.number("top-error", 0.0, 100.0) / 100.0);
  else
    line["mean_ratio_rgb"] = {m.mean_ratio_rgb.r, m.mean_ratio_rgb.g, m.mean_ratio_rgb.b};
  print_json(line);
  return 0;
}

}  // namespace transgi::cli
