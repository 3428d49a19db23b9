#include <algorithm>
#include <cstdio>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/image/exr.h"
#include "engine/image/tonemap.h"

namespace transgi::cli {

// Display an EXR: sRGB with exposure, or, with --signed S, the first channel
// through a diverging blue-white-red map where -S is blue and +S red (for SH
// coefficient maps). --minus B.exr subtracts B first (error maps).
int run_tonemap(const std::vector<std::string>& argv) {
  const Args args("tonemap", argv, {"exposure", "signed", "minus"});
  if (args.positional().size() != 2) throw UsageError("tonemap: expected IN.exr OUT.png");
  auto img = engine::image::read_exr(args.positional()[0]);
  if (args.has("minus")) {
    const auto b = engine::image::read_exr(args.str("minus"));
    if (b.width != img.width || b.height != img.height)
      throw std::runtime_error("--minus: " + args.str("minus") + " has a different size");
    for (std::size_t i = 0; i < img.size(); ++i) img.pixels[i] -= b.pixels[i];
  }
  if (!args.has("signed")) {
    engine::image::write_png_srgb(args.positional()[1], img, static_cast<float>(args.number("exposure", -30, 30, 0.0)));
    return 0;
  }
  const double scale = args.number("signed", 1e-12, 1e12);
  engine::image::Rgb8Image out(img.width, img.height);
  for (std::size_t i = 0; i < img.size(); ++i) {
    const double t = std::clamp(static_cast<double>(img.pixels[i].r) / scale, -1.0, 1.0);
    // White at zero, towards red for positive and blue for negative values.
    const double r = t >= 0 ? 1.0 : 1.0 + t, g = 1.0 - std::abs(t), b = t <= 0 ? 1.0 : 1.0 - t;
    out.pixels[i * 3 + 0] = static_cast<std::uint8_t>(std::lround(255 * r));
    out.pixels[i * 3 + 1] = static_cast<std::uint8_t>(std::lround(255 * g));
    out.pixels[i * 3 + 2] = static_cast<std::uint8_t>(std::lround(255 * b));
  }
  engine::image::write_png(args.positional()[1], out);
  return 0;
}

}  // namespace transgi::cli
