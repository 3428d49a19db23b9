#pragma once
// The run-time options render and bench-frame share: --preset, --gi-scale,
// --probe-budget, --map-width, --direct and --backend cpu|vulkan (with
// --device NAME), applied on top of the preset.
#include "cli/args.h"
#include "runtime/probe_placement.h"
#include "runtime/settings.h"

namespace transgi::cli {

runtime::TransGISettings runtime_settings_from(const Args& args, const char* default_preset);

// --probe-volume cascades|scene|authored, --probe-grid N (scene), --cascades N,
// --cascade-cell METRES (cascades; --probe-budget, read by
// runtime_settings_from, is the finest cascade's budget, halved per cascade).
runtime::ProbePlacement probe_placement_from(const Args& args, runtime::ProbeVolumeMode default_mode);

}  // namespace transgi::cli
