#include "engine/core/log.h"

#include <cstdio>

namespace engine::core {

const char* log_level_name(LogLevel level) {
  switch (level) {
    case LogLevel::Info: return "info";
    case LogLevel::Warning: return "warning";
    case LogLevel::Error: return "error";
  }
  return "?";
}

void Log::add(LogLevel level, std::string_view source, std::string_view text, std::uint64_t frame) {
  if (echo_)
    std::fprintf(stderr, "[%s] %.*s: %.*s\n", log_level_name(level), static_cast<int>(source.size()), source.data(),
                 static_cast<int>(text.size()), text.data());
  entries_.push_back({level, std::string(source), std::string(text), frame});
  ++total_;
  while (entries_.size() > capacity_) entries_.pop_front();
}

std::size_t Log::count(LogLevel level) const {
  std::size_t n = 0;
  for (const LogEntry& e : entries_) n += e.level == level ? 1 : 0;
  return n;
}

}  // namespace engine::core
