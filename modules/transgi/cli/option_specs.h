#pragma once
// The transgi tool's options, declared once each (engine::core::OptionSpec):
// the parser checks every read against these, and `transgi render --help`
// and the README's synopsis of `render` are printed from them.
#include <string>
#include <vector>

#include "engine/core/args.h"
#include "runtime/probe_placement.h"

namespace transgi::cli {

using engine::core::OptionSpec;

// What runtime_settings_from and near_field_from read (--preset, --gi-scale,
// --probe-budget, ..., --near-field-*); defaults from the presets, the
// preset itself `default_preset` (the command's).
std::vector<OptionSpec> runtime_option_specs(const std::string& default_preset);
// What probe_placement_from reads (--probe-volume, --probe-grid, --cascade-*).
std::vector<OptionSpec> placement_option_specs(runtime::ProbeVolumeMode default_mode);
// What apply_sun_options reads (--sun-elevation, --sun-azimuth).
std::vector<OptionSpec> sun_option_specs();

// Every option `render` accepts, and the line --help prints above them.
std::vector<OptionSpec> render_option_specs();
extern const char* const kRenderSynopsis;
// The same for `bench-frame`.
std::vector<OptionSpec> bench_frame_option_specs();
extern const char* const kBenchFrameSynopsis;
// The same for `fly-through` and `sun-sweep`.
std::vector<OptionSpec> fly_through_option_specs();
extern const char* const kFlyThroughSynopsis;
std::vector<OptionSpec> sun_sweep_option_specs();
extern const char* const kSunSweepSynopsis;

}  // namespace transgi::cli
