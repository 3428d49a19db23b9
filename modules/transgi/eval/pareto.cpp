#include "eval/pareto.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <map>
#include <sstream>

#include "engine/image/svg_plot.h"
#include "eval/text_output.h"

namespace transgi::eval {

namespace {

// The paper's Living Room ablations: (variant as we name it, time change ms, SSIM).
struct PaperRow {
  const char* variant;
  const char* time;
  const char* ssim;
  const char* ours = nullptr;  // our variant's name where it differs
};
constexpr PaperRow kPaperAblation[] = {
    {"map 200x100", "+6.0", "0.842"},
    {"map 50x25", "-0.5", "0.814"},
    {"probes 16^3", "+7.5", "0.867"},
    {"probes 4^3", "-0.2", "0.781"},
    {"latent 23", "+0.2", "0.841", "network: latent 23, width 128, depth 3"},
    {"rays 50", "-0.2", "0.822"},
    {"rays 200", "+1.5", "0.853"},
    {"default", "6.7 (total)", "0.839"},
};
// Its network table: (latent, width, depth) -> SSIM, decoder time ms.
constexpr PaperRow kPaperNetwork[] = {
    {"latent 7, width 96, depth 3", "0.9", "0.834"},  {"latent 7, width 128, depth 3", "1.5", "0.839"},
    {"latent 7, width 256, depth 3", "2.3", "0.839"}, {"latent 23, width 128, depth 3", "1.5", "0.842"},
    {"latent 55, width 128, depth 3", "1.6", "0.843"}, {"latent 7, width 128, depth 4", "2.0", "0.846"},
    {"latent 7, width 128, depth 5", "2.4", "0.851"},
};
}  // namespace

void mark_pareto_front(std::vector<ParetoPoint>& points) {
  for (auto& p : points) {
    p.on_front = std::none_of(points.begin(), points.end(), [&](const ParetoPoint& q) {
      return &q != &p && q.frame_ms <= p.frame_ms && q.rmse <= p.rmse && (q.frame_ms < p.frame_ms || q.rmse < p.rmse);
    });
  }
}

void write_pareto_csv(const std::filesystem::path& path, const std::vector<ParetoPoint>& points) {
  std::ostringstream o;
  o << "method,variant,group,frame_ms,rmse,l1,ssim,spp,pareto_front,inference_ms\n";
  for (const auto& p : points)
    o << '"' << p.method << "\",\"" << p.variant << "\"," << p.group << ',' << fmt("%.4f", p.frame_ms) << ',' << fmt("%.6f", p.rmse) << ','
      << fmt("%.6f", p.l1) << ',' << fmt("%.5f", p.ssim) << ',' << p.spp << ',' << (p.on_front ? 1 : 0) << ',' << fmt("%.4f", p.inference_ms) << '\n';
  write_text(path, o.str());
}

std::vector<ParetoPoint> read_pareto_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  std::vector<ParetoPoint> points;
  std::string line;
  std::getline(in, line);  // header
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    // "method","variant",group,frame_ms,rmse,l1,ssim,spp,pareto_front[,inference_ms]
    std::vector<std::string> f;
    std::string cur;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) {
        f.push_back(cur);
        cur.clear();
      } else cur += c;
    }
    f.push_back(cur);
    if (f.size() != 9 && f.size() != 10)
      throw std::runtime_error(path.string() + ": row " + std::to_string(row) + ": expected 10 fields, got " + std::to_string(f.size()));
    try {
      ParetoPoint p{f[0], f[1], f[2], std::stod(f[3]), std::stod(f[4]), std::stod(f[5]), std::stod(f[6]), std::stoi(f[7])};
      p.on_front = f[8] == "1";
      if (f.size() == 10) p.inference_ms = std::stod(f[9]);
      points.push_back(p);
    } catch (const std::exception&) {
      throw std::runtime_error(path.string() + ": row " + std::to_string(row) + ": a number field does not parse");
    }
  }
  return points;
}

void write_pareto_plot(const std::filesystem::path& path, const std::string& title, const std::vector<ParetoPoint>& points) {
  std::map<std::string, engine::image::PlotSeries> by_method;
  const std::map<std::string, std::string> colors = {{"TransGI", "#d62728"}, {"DDGI", "#1f77b4"}, {"path tracer (equal time)", "#7f7f7f"}};
  for (const auto& p : points) {
    auto& s = by_method[p.method];
    s.label = p.method;
    s.points = true;
    s.color = colors.contains(p.method) ? colors.at(p.method) : "#2ca02c";
    s.x.push_back(p.frame_ms);
    s.y.push_back(p.rmse);
  }
  std::vector<ParetoPoint> front;
  for (const auto& p : points)
    if (p.on_front) front.push_back(p);
  std::sort(front.begin(), front.end(), [](const ParetoPoint& a, const ParetoPoint& b) { return a.frame_ms < b.frame_ms; });
  engine::image::PlotSeries f{"Pareto front", {}, {}, "#000000", false};
  for (const auto& p : front) {
    f.x.push_back(p.frame_ms);
    f.y.push_back(p.rmse);
  }
  std::vector<engine::image::PlotSeries> series;
  for (auto& [name, s] : by_method) series.push_back(s);
  series.push_back(f);
  engine::image::write_svg_plot(path, {.title = title, .x_label = "frame time (ms, CPU, log)", .y_label = "GI RMSE (log)", .log_x = true, .log_y = true},
                                series);
}

void write_ablation_markdown(const std::filesystem::path& path, const std::string& header, const std::vector<ParetoPoint>& points) {
  std::ostringstream o;
  o << header << "\n\n## Ablation (the paper's Table 7 beside ours)\n\n"
    << "Time change against our default TransGI frame; the paper's times are one RTX-class GPU frame, ours the CPU oracle.\n\n"
    << "| variant | paper: time change (ms) | paper: SSIM | ours: time change (ms) | ours: SSIM | ours: RMSE |\n| --- | --- | --- | --- | --- | --- |\n";
  const ParetoPoint* base = nullptr;
  for (const auto& p : points)
    if (p.method == "TransGI" && p.variant == "default") base = &p;
  auto find = [&](const std::string& v) -> const ParetoPoint* {
    for (const auto& p : points)
      if (p.method == "TransGI" && p.variant == v) return &p;
    return nullptr;
  };
  for (const auto& row : kPaperAblation) {
    const ParetoPoint* p = find(row.ours ? row.ours : row.variant);
    // The network rows are re-baked (shorter than the main model): their time
    // change is against the re-baked default.
    const ParetoPoint* b = row.ours ? find("network: latent 7, width 128, depth 3") : base;
    if (!b) b = base;
    o << "| " << row.variant << " | " << row.time << " | " << row.ssim << " | ";
    if (p && b)
      o << (p == b ? fmt("%.1f (total)", p->frame_ms) : fmt("%+.1f", p->frame_ms - b->frame_ms)) << " | " << fmt("%.3f", p->ssim)
        << " | " << fmt("%.4f", p->rmse) << " |\n";
    else
      o << "not run | | |\n";
  }
  o << "\n## Network (the paper's Table 6 beside ours)\n\nEvery network row of ours is re-baked with the same dataset and iterations "
       "(the default row too), so they compare with each other; 'decoder ms' is our network-inference stage.\n\n"
    << "| latent, width, depth | paper: decoder ms | paper: SSIM | ours: decoder ms | ours: SSIM | ours: RMSE |\n| --- | --- | --- | --- | --- | --- |\n";
  for (const auto& row : kPaperNetwork) {
    o << "| " << row.variant << " | " << row.time << " | " << row.ssim << " | ";
    const ParetoPoint* p = find(std::string("network: ") + row.variant);
    if (p)
      o << fmt("%.1f", p->inference_ms) << " | " << fmt("%.3f", p->ssim) << " | " << fmt("%.4f", p->rmse) << " |\n";
    else
      o << "not run | | |\n";
  }
  for (const auto& p : points) {
    if (p.group != "network") continue;
    bool in_paper = false;
    for (const auto& row : kPaperNetwork) in_paper = in_paper || p.variant == std::string("network: ") + row.variant;
    if (!in_paper)
      o << "| " << p.variant.substr(9) << " | (not in the paper) | | " << fmt("%.1f", p.inference_ms) << " | " << fmt("%.3f", p.ssim) << " | "
        << fmt("%.4f", p.rmse) << " |\n";
  }
  write_text(path, o.str());
}

}  // namespace transgi::eval
