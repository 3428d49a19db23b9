#pragma once
// The engine's message log: a bounded list that an editor's log panel reads
// and that echoes to the console. A World resource; systems that report to
// a person (scripts, loaders, tools) add to it.
#include <cstdint>
#include <deque>
#include <string>
#include <string_view>

namespace engine::core {

enum class LogLevel : std::uint8_t { Info, Warning, Error };

struct LogEntry {
  LogLevel level = LogLevel::Info;
  std::string source;  // who said it: "script door.lua", "loader", ...
  std::string text;
  std::uint64_t frame = 0;
};

class Log {
 public:
  // capacity: entries kept (oldest dropped first); echo: also print each
  // entry to stderr, as "[level] source: text".
  explicit Log(std::size_t capacity = 1024, bool echo = true) : capacity_(capacity), echo_(echo) {}

  void add(LogLevel level, std::string_view source, std::string_view text, std::uint64_t frame = 0);
  void info(std::string_view source, std::string_view text) { add(LogLevel::Info, source, text); }
  void warning(std::string_view source, std::string_view text) { add(LogLevel::Warning, source, text); }
  void error(std::string_view source, std::string_view text) { add(LogLevel::Error, source, text); }

  [[nodiscard]] const std::deque<LogEntry>& entries() const { return entries_; }
  // Entries ever added, including those dropped; a panel scrolls when it grows.
  [[nodiscard]] std::uint64_t total() const { return total_; }
  [[nodiscard]] std::size_t count(LogLevel level) const;
  void set_echo(bool echo) { echo_ = echo; }
  void clear() { entries_.clear(); }

 private:
  std::size_t capacity_;
  bool echo_;
  std::uint64_t total_ = 0;
  std::deque<LogEntry> entries_;
};

const char* log_level_name(LogLevel level);

}  // namespace engine::core
