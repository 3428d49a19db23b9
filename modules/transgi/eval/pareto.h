#pragma once
// Run time against error: the points of a sweep, which of them are on the
// Pareto front (no other point is both faster and more accurate), and their
// CSV, plot and ablation-table renderings.
#include <filesystem>
#include <string>
#include <vector>

namespace transgi::eval {

struct ParetoPoint {
  std::string method;   // "TransGI", "DDGI", "path tracer (equal time)"
  std::string variant;  // "default", "probes 4^3", ...
  std::string group;    // ablation group: "probes", "rays", "map", "network", "" for defaults
  double frame_ms = 0;
  double rmse = 0, l1 = 0, ssim = 0;
  int spp = 0;          // path tracer only
  double inference_ms = 0;  // TransGI: its network-inference stage
  bool on_front = false;
};

// Marks points not dominated in (frame_ms, rmse): lower is better in both.
void mark_pareto_front(std::vector<ParetoPoint>& points);

void write_pareto_csv(const std::filesystem::path& path, const std::vector<ParetoPoint>& points);
// Reads what write_pareto_csv wrote (to re-render the plot and tables).
std::vector<ParetoPoint> read_pareto_csv(const std::filesystem::path& path);
void write_pareto_plot(const std::filesystem::path& path, const std::string& title, const std::vector<ParetoPoint>& points);
// Our ablation rows (time change against the default, SSIM, RMSE) beside
// the paper's Living Room rows (its Tables 6 and 7).
void write_ablation_markdown(const std::filesystem::path& path, const std::string& header, const std::vector<ParetoPoint>& points);

}  // namespace transgi::eval
