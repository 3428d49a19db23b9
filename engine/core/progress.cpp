#include "engine/core/progress.h"

#include <cmath>
#include <cstdio>

#include <unistd.h>

namespace engine::core {

std::string format_duration(double s) {
  char buf[32];
  if (!std::isfinite(s) || s < 0) return "?";
  if (s < 60) std::snprintf(buf, sizeof(buf), "%.1fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof(buf), "%dm %02ds", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  else std::snprintf(buf, sizeof(buf), "%dh %02dm", static_cast<int>(s) / 3600, (static_cast<int>(s) / 60) % 60);
  return buf;
}

ProgressBar::ProgressBar(std::string label, std::uint64_t total, bool enabled)
    : label_(std::move(label)),
      total_(total ? total : 1),
      enabled_(enabled),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() {
  if (!finished_) finish();
}

double ProgressBar::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressBar::update(std::uint64_t done, const std::string& note) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const int decile = static_cast<int>(10 * done / total_);
  if (tty_ ? now - last_draw_ < std::chrono::milliseconds(200) : decile == last_decile_) return;
  last_draw_ = now;
  last_decile_ = decile;
  draw(done, note, false);
}

void ProgressBar::finish(const std::string& note) {
  if (finished_) return;
  finished_ = true;
  if (enabled_) draw(total_, note, true);
}

void ProgressBar::draw(std::uint64_t done, const std::string& note, bool final) {
  const double frac = std::min(1.0, static_cast<double>(done) / static_cast<double>(total_));
  const double elapsed = elapsed_seconds();
  const double eta = frac > 0 ? elapsed * (1 - frac) / frac : -1;
  constexpr int kWidth = 30;
  const int filled = static_cast<int>(frac * kWidth);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(kWidth, '-');
  std::fprintf(stderr, "%s%s [%s] %5.1f%%  %s  %s%s%s%s", tty_ ? "\r" : "", label_.c_str(), bar.c_str(), 100 * frac,
               final ? ("done in " + format_duration(elapsed)).c_str()
                     : ("elapsed " + format_duration(elapsed) + ", ETA " + format_duration(eta)).c_str(),
               note.c_str(), tty_ ? "\033[K" : "", final || !tty_ ? "\n" : "", "");
  std::fflush(stderr);
}

}  // namespace engine::core
