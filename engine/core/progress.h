#pragma once
// A progress bar with an estimated time left, written to stderr. On a
// terminal it redraws one line; otherwise (CI logs) it prints a line at
// every 10 % so logs stay short.
#include <chrono>
#include <cstdint>
#include <string>

namespace engine::core {

class ProgressBar {
 public:
  ProgressBar(std::string label, std::uint64_t total, bool enabled = true);
  ~ProgressBar();
  void update(std::uint64_t done, const std::string& note = {});
  void finish(const std::string& note = {});
  [[nodiscard]] double elapsed_seconds() const;

 private:
  void draw(std::uint64_t done, const std::string& note, bool final);
  std::string label_;
  std::uint64_t total_;
  bool enabled_, tty_, finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_draw_;
};

// "1m 05s", "12.3s"
std::string format_duration(double seconds);

}  // namespace engine::core
