#include "eval/eval_report.h"

#include <cstdio>
#include <sstream>

#include "eval/text_output.h"

namespace transgi::eval {

namespace {

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    o += c;
  }
  return o + "\"";
}

std::string json_metrics(const engine::image::ErrorMetrics& m) {
  return "{\"rmse\": " + fmt("%.6g", m.rmse) + ", \"l1\": " + fmt("%.6g", m.l1) + ", \"ssim\": " + fmt("%.6g", m.ssim) +
         ", \"relmse\": " + fmt("%.6g", m.relmse) + ", \"mean_ratio\": " + fmt("%.4f", m.mean_ratio) + "}";
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

void write_results_json(const std::filesystem::path& path, const EvalReport& r) {
  std::ostringstream o;
  o << "{\n  \"scene\": " << json_string(r.scene) << ",\n  \"command\": " << json_string(r.command) << ",\n  \"width\": " << r.width
    << ", \"height\": " << r.height << ",\n  \"reference\": {\"spp\": " << r.reference_spp
    << ", \"seconds\": " << fmt("%.3f", r.reference_seconds) << ", \"cached\": " << (r.reference_cached ? "true" : "false")
    << ", \"key\": " << json_string(r.reference_key) << ", \"mean_spp\": " << fmt("%.1f", r.reference_mean_spp)
    << ", \"target_error\": " << fmt("%g", r.reference_target_error) << ", \"noise_rmse_gi\": " << fmt("%.6f", r.reference_noise_gi)
    << ", \"noise_rmse_full\": " << fmt("%.6f", r.reference_noise_full) << "},\n  \"methods\": [\n";
  for (std::size_t i = 0; i < r.methods.size(); ++i) {
    const auto& m = r.methods[i];
    o << "    {\"name\": " << json_string(m.name) << ", \"settings\": " << json_string(m.settings) << ",\n     \"gi\": " << json_metrics(m.gi)
      << ",\n     \"gi_di\": " << json_metrics(m.gi_di) << ",\n     \"frame_ms\": " << fmt("%.4f", m.run.frame_ms) << ", \"stages_ms\": {";
    for (std::size_t s = 0; s < m.run.stages.size(); ++s)
      o << (s ? ", " : "") << json_string(m.run.stages[s].name) << ": " << fmt("%.4f", m.run.stages[s].ms);
    o << "},\n     \"probe_bytes\": " << m.run.probe_bytes << ", \"probes\": " << json_string(m.run.probe_summary) << "}"
      << (i + 1 < r.methods.size() ? "," : "") << "\n";
  }
  o << "  ],\n  \"memory\": {\"vertices\": " << r.vertices << ", \"latent_rows\": " << r.latent_rows << ", \"latent_dim\": " << r.latent_dim
    << ", \"decoder_bytes\": " << r.decoder_bytes << ", \"latent_bytes\": " << r.latent_bytes << "},\n  \"bake_settings\": "
    << (r.bake_settings.empty() ? "null" : r.bake_settings) << "\n}\n";
  write_text(path, o.str());
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
