#include "engine/core/args.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace engine::core {

Args::Args(std::string command, const std::vector<std::string>& argv, std::set<std::string> known,
           std::set<std::string> flags)
    : command_(std::move(command)) {
  if (!flags.contains("help") && !known.contains("help"))
    for (const std::string& a : argv)
      if (a == "--help") {
        std::string text = command_ + ": the options it accepts:\n ";
        std::size_t column = 1;
        const auto add = [&](const std::string& item) {
          if (column + item.size() + 1 > 110) {
            text += "\n ";
            column = 1;
          }
          text += " " + item;
          column += item.size() + 1;
        };
        for (const std::string& name : known) add("--" + name + " V");
        for (const std::string& name : flags) add("--" + name);
        throw HelpRequested(text + "\n");
      }
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& a = argv[i];
    if (a.rfind("--", 0) != 0) {
      positional_.push_back(a);
      continue;
    }
    const std::string name = a.substr(2);
    if (flags.contains(name)) {
      set_flags_.insert(name);
    } else if (known.contains(name)) {
      if (i + 1 >= argv.size()) fail(name, "needs a value");
      if (values_.contains(name)) fail(name, "given twice");
      values_[name] = argv[++i];
    } else {
      fail(name, "unknown option");
    }
  }
}

void Args::fail(const std::string& name, const std::string& why) const {
  throw UsageError(command_ + ": --" + name + ": " + why);
}

std::string Args::str(const std::string& name, std::optional<std::string> fallback) const {
  auto it = values_.find(name);
  if (it != values_.end()) return it->second;
  if (fallback) return *fallback;
  fail(name, "is required");
}

std::int64_t Args::integer(const std::string& name, std::int64_t lo, std::int64_t hi,
                           std::optional<std::int64_t> fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) {
    if (fallback) return *fallback;
    fail(name, "is required");
  }
  const std::string& s = it->second;
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi)
    fail(name, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + s + "'");
  return v;
}

double Args::number(const std::string& name, double lo, double hi, std::optional<double> fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) {
    if (fallback) return *fallback;
    fail(name, "is required");
  }
  const std::string& s = it->second;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi)
    fail(name, "expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + s + "'");
  return v;
}

std::string Args::choice(const std::string& name, const std::vector<std::string>& allowed,
                         std::optional<std::string> fallback) const {
  const std::string v = str(name, fallback);
  for (const auto& a : allowed)
    if (a == v) return v;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : "|") + a;
  fail(name, "expected one of " + list + ", got '" + v + "'");
}

}  // namespace engine::core
