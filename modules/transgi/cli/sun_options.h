#pragma once
// --sun-elevation DEG / --sun-azimuth DEG: turn the scene's first directional
// light (engine/scene/sun.h) before anything renders; the angle not given
// keeps its value from the scene.
#include "cli/args.h"
#include "eval/method_runs.h"

namespace transgi::cli {

// Returns whether the sun was turned (and the scene updated so its world
// transforms, Embree mirror and lights follow).
bool apply_sun_options(const Args& args, eval::LoadedScene& scene);

}  // namespace transgi::cli
