// The command-line parser (engine::core::Args, as every transgi command uses
// it) on untrusted argument lists: one token per line of the input. Each bad
// option must end in a UsageError naming it, never a crash, and a value that
// passes must lie within its declared range.
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/runtime_options.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> argv(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') {
      argv.emplace_back();
      continue;
    }
    argv.back() += static_cast<char>(data[i]);
  }
  try {
    // render's declared options (cmd_render.cpp), read as render reads them.
    const transgi::cli::Args args("render", argv,
                                  {"scene", "method", "pass", "spp", "width", "height", "out", "camera", "seed", "threads", "png",
                                   "exposure", "model", "transfer", "gt-rays", "frames", "probe-grid", "probe-rays", "direct-spp",
                                   "probe-skip", "hysteresis", "preset", "gi-scale", "probe-budget", "direct", "map-width"},
                                  {"resume"});
    (void)args.str("scene", std::string());
    (void)args.choice("method", {"reference", "transgi", "ddgi"}, "reference");
    const double exposure = args.number("exposure", -30, 30, 0.0);
    const long long width = args.integer("width", 1, 16384, 320);
    const long long seed = args.integer("seed", 0, INT64_MAX, 0);
    const double hysteresis = args.number("hysteresis", 0.0, 1.0, 0.97);
    if (!(exposure >= -30 && exposure <= 30) || width < 1 || width > 16384 || seed < 0 || !(hysteresis >= 0 && hysteresis <= 1))
      std::abort();  // a value outside its declared range got through
    const transgi::runtime::TransGISettings s = transgi::cli::runtime_settings_from(args, "realtime");
    if (!std::isfinite(s.realtime.resolution_scale) || s.probes.map.width < 4) std::abort();
  } catch (const transgi::cli::UsageError&) {
  } catch (const std::exception&) {
  }
  return 0;
}
