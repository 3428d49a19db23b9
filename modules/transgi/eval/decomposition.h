#pragma once
// Where TransGI's error comes from (issue 14, item 2): after a normal run,
// the same probe state is rendered again with one part replaced by its
// oracle at a time, and the GI error that remains is measured:
//   - the network replaced by the ground-truth transfer of each sample;
//   - the probes replaced by path-traced oracle probes (same SH projection);
//   - the G-buffer at 16 samples per pixel instead of 1;
//   - both oracles together: what is left is SH-4 truncation, probe
//     interpolation and the G-buffer.
// Each row's share is the fraction of the squared error (RMSE^2) it removes.
#include <filesystem>
#include <string>
#include <vector>

#include "engine/image/image.h"
#include "engine/image/metrics.h"
#include "eval/method_runs.h"

namespace transgi::eval {

struct DecompositionOptions {
  int oracle_rays_per_texel = 16;  // paths per probe map texel
  int ground_truth_rays = 512;     // per sample, for the transfer oracle
  int gbuffer_spp = 16;
};

struct DecompositionRow {
  std::string name;  // what was replaced
  std::string slug;  // file name
  engine::image::ImageRGB gi;
  engine::image::ErrorMetrics metrics;
  double share = 0;  // of the base row's squared error removed (negative: it grew)
};

// `scene` must have run TransGI (run_transgi) with the quality GI path: its
// probes are kept, frozen, and rendered again. The first row is the run's
// own state re-rendered.
std::vector<DecompositionRow> decompose_transgi(LoadedScene& scene, const engine::image::ImageRGB& reference_gi, int width,
                                                int height, const DecompositionOptions& options);

// decomposition.md (the table, the reference noise) and one error map per
// row on one scale under heat/, images under images/.
void write_decomposition(const std::filesystem::path& dir, const std::vector<DecompositionRow>& rows,
                         const engine::image::ImageRGB& reference_gi, double reference_noise, const std::string& command);

}  // namespace transgi::eval
