#include "cli/runtime_options.h"

#include <algorithm>

#include "runtime/transgi_plugin.h"

namespace transgi::cli {

runtime::TransGISettings runtime_settings_from(const Args& args, const char* default_preset) {
  runtime::TransGISettings s = args.choice("preset", {"quality", "realtime"}, default_preset) == "realtime"
                                   ? runtime::realtime_preset()
                                   : runtime::quality_preset();
  s.realtime.resolution_scale = static_cast<float>(args.number("gi-scale", 0.05, 1.0, s.realtime.resolution_scale));
  s.probes.update_budget = static_cast<int>(args.integer("probe-budget", 0, 1 << 20, s.probes.update_budget));
  s.probes.map.width = static_cast<int>(args.integer("map-width", 4, 4096, s.probes.map.width));
  s.probes.map.height = std::max(2, s.probes.map.width / 2);
  if (args.has("direct"))
    s.direct_light = args.choice("direct", {"deterministic", "stochastic"}, "stochastic") == "deterministic"
                         ? runtime::DirectLight::Deterministic
                         : runtime::DirectLight::Stochastic;
  return s;
}

}  // namespace transgi::cli
