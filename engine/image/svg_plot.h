#pragma once
// Minimal SVG line/scatter plots for reports (training curves, time vs
// error). Deterministic text output, written atomically.
#include <filesystem>
#include <string>
#include <vector>

namespace engine::image {

struct PlotSeries {
  std::string label;
  std::vector<double> x, y;
  std::string color = "#1f77b4";
  bool points = false;  // markers instead of a line
};

struct PlotSpec {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;
  int width = 640, height = 400;
};

void write_svg_plot(const std::filesystem::path& path, const PlotSpec& spec, const std::vector<PlotSeries>& series);

}  // namespace engine::image
