#pragma once
// The run-time options render and bench-frame share: --preset, --gi-scale,
// --probe-budget, --map-width and --direct, applied on top of the preset.
#include "cli/args.h"
#include "runtime/settings.h"

namespace transgi::cli {

runtime::TransGISettings runtime_settings_from(const Args& args, const char* default_preset);

}  // namespace transgi::cli
