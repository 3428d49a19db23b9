#include "engine/image/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>

#include "engine/io/atomic_file.h"

namespace engine::image {

namespace {
std::string fmt(double v) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.4g", v);
  return b;
}
std::string escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '<') o += "&lt;";
    else if (c == '>') o += "&gt;";
    else if (c == '&') o += "&amp;";
    else o += c;
  }
  return o;
}
}  // namespace

void write_svg_plot(const std::filesystem::path& path, const PlotSpec& spec, const std::vector<PlotSeries>& series) {
  auto tx = [&](double v) { return spec.log_x ? std::log10(v) : v; };
  auto ty = [&](double v) { return spec.log_y ? std::log10(v) : v; };
  double x0 = std::numeric_limits<double>::max(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const auto& s : series)
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if ((spec.log_x && s.x[i] <= 0) || (spec.log_y && s.y[i] <= 0) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x0 = std::min(x0, tx(s.x[i]));
      x1 = std::max(x1, tx(s.x[i]));
      y0 = std::min(y0, ty(s.y[i]));
      y1 = std::max(y1, ty(s.y[i]));
    }
  if (x0 > x1) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 - x0 < 1e-12) x1 = x0 + 1;
  if (y1 - y0 < 1e-12) y1 = y0 + 1;
  const double pad_y = 0.05 * (y1 - y0);
  y0 -= pad_y;
  y1 += pad_y;
  const int L = 70, R = 20, T = 40, B = 50, W = spec.width, H = spec.height;
  auto px = [&](double v) { return L + (tx(v) - x0) / (x1 - x0) * (W - L - R); };
  auto py = [&](double v) { return H - B - (ty(v) - y0) / (y1 - y0) * (H - T - B); };

  std::string svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(W) + "\" height=\"" + std::to_string(H) +
                    "\" font-family=\"sans-serif\" font-size=\"12\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg += "<text x=\"" + std::to_string(W / 2) + "\" y=\"20\" text-anchor=\"middle\" font-size=\"14\">" + escape(spec.title) + "</text>\n";
  svg += "<rect x=\"" + std::to_string(L) + "\" y=\"" + std::to_string(T) + "\" width=\"" + std::to_string(W - L - R) +
         "\" height=\"" + std::to_string(H - T - B) + "\" fill=\"none\" stroke=\"black\"/>\n";
  for (int i = 0; i <= 5; ++i) {
    const double fx = x0 + (x1 - x0) * i / 5, fy = y0 + (y1 - y0) * i / 5;
    const double vx = spec.log_x ? std::pow(10.0, fx) : fx, vy = spec.log_y ? std::pow(10.0, fy) : fy;
    const double gx = L + (W - L - R) * i / 5.0, gy = H - B - (H - T - B) * i / 5.0;
    svg += "<line x1=\"" + fmt(gx) + "\" y1=\"" + std::to_string(T) + "\" x2=\"" + fmt(gx) + "\" y2=\"" + std::to_string(H - B) +
           "\" stroke=\"#ddd\"/><text x=\"" + fmt(gx) + "\" y=\"" + std::to_string(H - B + 16) + "\" text-anchor=\"middle\">" + fmt(vx) + "</text>\n";
    svg += "<line x1=\"" + std::to_string(L) + "\" y1=\"" + fmt(gy) + "\" x2=\"" + std::to_string(W - R) + "\" y2=\"" + fmt(gy) +
           "\" stroke=\"#ddd\"/><text x=\"" + std::to_string(L - 6) + "\" y=\"" + fmt(gy + 4) + "\" text-anchor=\"end\">" + fmt(vy) + "</text>\n";
  }
  svg += "<text x=\"" + std::to_string((L + W - R) / 2) + "\" y=\"" + std::to_string(H - 12) + "\" text-anchor=\"middle\">" + escape(spec.x_label) + "</text>\n";
  svg += "<text transform=\"translate(16," + std::to_string((T + H - B) / 2) + ") rotate(-90)\" text-anchor=\"middle\">" + escape(spec.y_label) + "</text>\n";
  int legend = 0;
  for (const auto& s : series) {
    std::string pts;
    for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if ((spec.log_x && s.x[i] <= 0) || (spec.log_y && s.y[i] <= 0) || !std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      if (s.points) svg += "<circle cx=\"" + fmt(px(s.x[i])) + "\" cy=\"" + fmt(py(s.y[i])) + "\" r=\"3\" fill=\"" + s.color + "\"/>\n";
      else pts += fmt(px(s.x[i])) + "," + fmt(py(s.y[i])) + " ";
    }
    if (!s.points) svg += "<polyline fill=\"none\" stroke=\"" + s.color + "\" stroke-width=\"1.5\" points=\"" + pts + "\"/>\n";
    const int ly = T + 14 + 16 * legend++;
    svg += "<rect x=\"" + std::to_string(W - R - 190) + "\" y=\"" + std::to_string(ly - 9) + "\" width=\"10\" height=\"10\" fill=\"" + s.color +
           "\"/><text x=\"" + std::to_string(W - R - 175) + "\" y=\"" + std::to_string(ly) + "\">" + escape(s.label) + "</text>\n";
  }
  svg += "</svg>\n";
  io::write_file_atomically(path, std::as_bytes(std::span(svg.data(), svg.size())));
}

}  // namespace engine::image
