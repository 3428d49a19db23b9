#include <cstdio>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/image/exr.h"
#include "engine/image/tonemap.h"

namespace transgi::cli {

int run_tonemap(const std::vector<std::string>& argv) {
  const Args args("tonemap", argv, {"exposure"});
  if (args.positional().size() != 2) throw UsageError("tonemap: expected IN.exr OUT.png");
  const auto img = engine::image::read_exr(args.positional()[0]);
  engine::image::write_png_srgb(args.positional()[1], img, static_cast<float>(args.number("exposure", -30, 30, 0.0)));
  return 0;
}

}  // namespace transgi::cli
