#pragma once
// The path tracer's GI pass of a loaded scene as it stands now, from its
// camera: the reference that bench-frame, sun-sweep and fly-through compare a
// frame with. Lights as the scene has them (no sun split: the reference's own
// estimator), seed 1.
#include <functional>

#include "engine/image/image.h"
#include "eval/method_runs.h"

namespace transgi::cli {

engine::image::ImageRGB reference_gi_now(eval::LoadedScene& scene, int width, int height, int spp,
                                         const std::function<void(int done, int total)>& progress = {});

}  // namespace transgi::cli
