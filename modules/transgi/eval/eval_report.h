#pragma once
// What `transgi eval` measured, and its three renderings: results.json (for
// scripts), results.md (the paper's Tables 1, 2, 4 and 5 for this scene) and
// index.html (the images side by side with their error maps).
#include <filesystem>
#include <string>
#include <vector>

#include "engine/image/metrics.h"
#include "eval/method_runs.h"

namespace transgi::eval {

struct MethodResult {
  std::string name;        // "TransGI", "DDGI"
  std::string slug;        // file-name prefix: "transgi", "ddgi"
  std::string settings;    // one line: what was run
  MethodRun run;
  engine::image::ErrorMetrics gi;     // GI only vs the reference gi pass
  engine::image::ErrorMetrics gi_di;  // GI + the reference's direct vs the reference full
};

struct EvalReport {
  std::string scene, command;
  int width = 0, height = 0;
  int reference_spp = 0;
  double reference_seconds = 0;
  bool reference_cached = false;
  std::string reference_key;
  double reference_mean_spp = 0;
  float reference_target_error = 0;             // 0 = uniform sampling
  double reference_noise_gi = 0, reference_noise_full = 0;  // estimated RMSE (two halves)
  std::string reference_note;                   // the noise line, and a warning if it is too high
  std::vector<MethodResult> methods;
  // Table 5: the model's memory.
  std::size_t vertices = 0, latent_rows = 0, decoder_bytes = 0, latent_bytes = 0;
  int latent_dim = 0;
  std::string bake_settings;  // JSON from the model file
};

void write_results_json(const std::filesystem::path& path, const EvalReport& r);
void write_results_markdown(const std::filesystem::path& path, const EvalReport& r);
void write_index_html(const std::filesystem::path& path, const EvalReport& r);

}  // namespace transgi::eval
