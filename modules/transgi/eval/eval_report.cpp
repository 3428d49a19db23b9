#include "eval/eval_report.h"

#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include "eval/text_output.h"

namespace transgi::eval {

namespace {

nlohmann::ordered_json json_metrics(const engine::image::ErrorMetrics& m) {
  return {{"rmse", m.rmse}, {"l1", m.l1}, {"ssim", m.ssim}, {"relmse", m.relmse}, {"mean_ratio", m.mean_ratio}};
}

std::string html_escape(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '<' ? "&lt;" : c == '>' ? "&gt;" : c == '&' ? "&amp;" : std::string(1, c);
  return o;
}

// Marks the best value of a column in bold.
std::string cell(double v, double best, const char* f) { return v == best ? "**" + fmt(f, v) + "**" : fmt(f, v); }

std::string metrics_table(const EvalReport& r, bool with_di) {
  std::ostringstream o;
  o << "| Method | RMSE | L1 | SSIM | mean / reference mean |\n| --- | --- | --- | --- | --- |\n";
  double best_rmse = 1e30, best_l1 = 1e30, best_ssim = -1e30;
  for (const auto& m : r.methods) {
    const auto& e = with_di ? m.gi_di : m.gi;
    best_rmse = std::min(best_rmse, e.rmse);
    best_l1 = std::min(best_l1, e.l1);
    best_ssim = std::max(best_ssim, e.ssim);
  }
  for (const auto& m : r.methods) {
    const auto& e = with_di ? m.gi_di : m.gi;
    o << "| " << m.name << (with_di ? "+DI" : "") << " | " << cell(e.rmse, best_rmse, "%.4f") << " | " << cell(e.l1, best_l1, "%.4f")
      << " | " << cell(e.ssim, best_ssim, "%.3f") << " | " << fmt("%.3f", e.mean_ratio) << " |\n";
  }
  return o.str();
}

std::string timing_table(const EvalReport& r) {
  std::ostringstream o;
  o << "| Method | Stage | Time (ms) |\n| --- | --- | --- |\n";
  for (const auto& m : r.methods) {
    for (const auto& s : m.run.stages)
      if (s.name != "direct light") o << "| " << m.name << " | " << s.name << " | " << fmt("%.2f", s.ms) << " |\n";
    o << "| " << m.name << " | **Total** | **" << fmt("%.2f", m.run.frame_ms) << "** |\n";
  }
  return o.str();
}

}  // namespace

// Through nlohmann-json: strings escaped whatever they hold, a non-finite
// number written as null (JSON has no NaN).
void write_results_json(const std::filesystem::path& path, const EvalReport& r) {
  nlohmann::ordered_json methods = nlohmann::ordered_json::array();
  for (const auto& m : r.methods) {
    nlohmann::ordered_json stages = nlohmann::ordered_json::object();
    for (const auto& s : m.run.stages) stages[s.name] = s.ms;
    methods.push_back({{"name", m.name},
                       {"settings", m.settings},
                       {"gi", json_metrics(m.gi)},
                       {"gi_di", json_metrics(m.gi_di)},
                       {"frame_ms", m.run.frame_ms},
                       {"stages_ms", stages},
                       {"probe_bytes", m.run.probe_bytes},
                       {"probes", m.run.probe_summary}});
  }
  // The model's bake settings are JSON already; kept as text where they do not parse.
  nlohmann::ordered_json bake = nullptr;
  if (!r.bake_settings.empty()) {
    bake = nlohmann::ordered_json::parse(r.bake_settings, nullptr, /*allow_exceptions=*/false);
    if (bake.is_discarded()) bake = r.bake_settings;
  }
  const nlohmann::ordered_json j{{"scene", r.scene},
                         {"command", r.command},
                         {"width", r.width},
                         {"height", r.height},
                         {"reference",
                          {{"spp", r.reference_spp},
                           {"seconds", r.reference_seconds},
                           {"cached", r.reference_cached},
                           {"key", r.reference_key},
                           {"mean_spp", r.reference_mean_spp},
                           {"target_error", r.reference_target_error},
                           {"noise_rmse_gi", r.reference_noise_gi},
                           {"noise_rmse_full", r.reference_noise_full}}},
                         {"methods", methods},
                         {"memory",
                          {{"vertices", r.vertices},
                           {"latent_rows", r.latent_rows},
                           {"latent_dim", r.latent_dim},
                           {"decoder_bytes", r.decoder_bytes},
                           {"latent_bytes", r.latent_bytes}}},
                         {"bake_settings", bake}};
  write_text(path, j.dump(2) + "\n");
}

void write_results_markdown(const std::filesystem::path& path, const EvalReport& r) {
  std::ostringstream o;
  o << "# Evaluation: " << r.scene << "\n\n" << r.width << "x" << r.height << ", reference: path tracer, "
    << (r.reference_target_error > 0 ? "adaptive to relative error " + fmt("%g", r.reference_target_error) + " per pixel (at most " +
                                           std::to_string(r.reference_spp) + " spp), "
                                     : std::to_string(r.reference_spp) + " spp, ")
    << fmt("%.0f", r.reference_mean_spp) << " spp on average (" << (r.reference_cached ? "cached, " : "") << fmt("%.1f", r.reference_seconds)
    << " s).\n\nCommand: `" << r.command << "`\n\n";
  for (const auto& m : r.methods) o << "- " << m.name << ": " << m.settings << "; " << m.run.probe_summary << "\n";
  const std::string noise = "\nThe reference's own noise, estimated from two independent halves: RMSE " + fmt("%.4f", r.reference_noise_gi) +
                            " (GI), " + fmt("%.4f", r.reference_noise_full) + " (full). " +
                            (r.reference_note.find("warning") != std::string::npos ? "**It exceeds 1/5 of the smallest error in these tables.**\n"
                                                                                    : "Below 1/5 of every error in these tables.\n");
  o << "\n## GI only (Table 1)\n\n" << metrics_table(r, false) << noise << "\n## GI + DI (Table 2; DI = the reference's direct pass)\n\n"
    << metrics_table(r, true) << noise << "\n## Per-stage times, one frame (Table 4)\n\nMedians of the last timed frames; the CPU oracle path, "
    << "2 threads unless stated.\n\n" << timing_table(r) << "\n## Memory (Table 5)\n\n| Vertices (welded) | Network (KB) | Vertex features (MB) |"
    << " Probe storage TransGI / DDGI (MB) |\n| --- | --- | --- | --- |\n| " << r.vertices << " (" << r.latent_rows << ") | "
    << fmt("%.1f", static_cast<double>(r.decoder_bytes) / 1024.0) << " | " << fmt("%.2f", static_cast<double>(r.latent_bytes) / (1024.0 * 1024.0))
    << " | ";
  for (std::size_t i = 0; i < r.methods.size(); ++i)
    o << (i ? " / " : "") << fmt("%.2f", static_cast<double>(r.methods[i].run.probe_bytes) / (1024.0 * 1024.0));
  o << " |\n";
  write_text(path, o.str());
}

void write_index_html(const std::filesystem::path& path, const EvalReport& r) {
  std::ostringstream o;
  o << "<!doctype html><html><head><meta charset=\"utf-8\"><title>TransGI evaluation: " << html_escape(r.scene)
    << "</title><style>body{font-family:sans-serif;margin:2em}img{width:32%;image-rendering:pixelated}"
       "table{border-collapse:collapse}td,th{border:1px solid #999;padding:2px 8px}figure{display:inline-block;width:32%;margin:0}"
       "figure img{width:100%}</style></head><body>\n<h1>"
    << html_escape(r.scene) << "</h1><p>" << r.width << "x" << r.height << ", reference " << r.reference_spp << " spp. <code>"
    << html_escape(r.command) << "</code></p>\n";
  for (const char* setup : {"gi", "full"}) {
    const bool gi = std::string(setup) == "gi";
    o << "<h2>" << (gi ? "GI only" : "GI + DI") << "</h2>\n<div><figure><img src=\"images/reference_" << setup
      << ".png\"><figcaption>reference</figcaption></figure>";
    for (const auto& m : r.methods) {
      const auto& e = gi ? m.gi : m.gi_di;
      o << "<figure><img src=\"images/" << m.slug << "_" << setup << ".png\"><figcaption>" << html_escape(m.name) << ": RMSE "
        << fmt("%.4f", e.rmse) << ", SSIM " << fmt("%.3f", e.ssim) << "</figcaption></figure>";
    }
    o << "</div>\n<div><figure></figure>";
    for (const auto& m : r.methods)
      o << "<figure><img src=\"heat/" << m.slug << "_" << setup << ".png\"><figcaption>" << html_escape(m.name)
        << " error (black 0, white = the same maximum for all methods)</figcaption></figure>";
    o << "</div>\n";
  }
  o << "<h2>Tables</h2><p>The same numbers as <a href=\"results.md\">results.md</a> and <a href=\"results.json\">results.json</a>.</p>"
    << "<table><tr><th>method</th><th>GI RMSE</th><th>GI L1</th><th>GI SSIM</th><th>GI+DI RMSE</th><th>GI+DI L1</th><th>GI+DI SSIM</th>"
       "<th>frame (ms)</th></tr>";
  for (const auto& m : r.methods)
    o << "<tr><td>" << html_escape(m.name) << "</td><td>" << fmt("%.4f", m.gi.rmse) << "</td><td>" << fmt("%.4f", m.gi.l1) << "</td><td>"
      << fmt("%.3f", m.gi.ssim) << "</td><td>" << fmt("%.4f", m.gi_di.rmse) << "</td><td>" << fmt("%.4f", m.gi_di.l1) << "</td><td>"
      << fmt("%.3f", m.gi_di.ssim) << "</td><td>" << fmt("%.2f", m.run.frame_ms) << "</td></tr>";
  o << "</table><h3>Stages (ms)</h3><table>";
  for (const auto& m : r.methods)
    for (const auto& s : m.run.stages) o << "<tr><td>" << html_escape(m.name) << "</td><td>" << html_escape(s.name) << "</td><td>" << fmt("%.2f", s.ms) << "</td></tr>";
  o << "</table></body></html>\n";
  write_text(path, o.str());
}

}  // namespace transgi::eval
