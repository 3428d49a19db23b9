#pragma once
// The run-time options render and bench-frame share: --preset, --gi-scale,
// --probe-budget, --map-width, --direct and --backend cpu|vulkan (with
// --device NAME) and the near field's, applied on top of the preset.
#include "cli/args.h"
#include "runtime/probe_placement.h"
#include "runtime/settings.h"

namespace transgi::cli {

runtime::TransGISettings runtime_settings_from(const Args& args, const char* default_preset);

// --near-field-rays N, --near-field-reach CELLS, --near-field-filter RADIUS
// over `n` (eval builds its settings without a preset, so it calls this alone).
void near_field_from(const Args& args, shading::NearFieldRays& n);

// --probe-volume cascades|scene|authored, --probe-grid N (scene), --cascades N,
// --cascade-cell METRES (cascades; --probe-budget, read by
// runtime_settings_from, is the finest cascade's budget, halved per cascade).
runtime::ProbePlacement probe_placement_from(const Args& args, runtime::ProbeVolumeMode default_mode);

}  // namespace transgi::cli
