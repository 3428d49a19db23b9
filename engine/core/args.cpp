#include "engine/core/args.h"

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

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
  parse(argv, known, flags);
}

namespace {

std::string format_bound(double v) {
  if (v == static_cast<double>(INT64_MAX)) return "2^63-1";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

std::string describe_options(const std::vector<OptionSpec>& specs) {
  std::string text;
  for (const OptionSpec& o : specs) {
    std::string head = "  --" + o.name + (o.flag ? "" : " " + o.value);
    if (head.size() < 30) head.resize(30, ' ');
    std::string accepts;
    if (o.range) accepts = format_bound(o.range->first) + ".." + format_bound(o.range->second);
    for (const std::string& c : o.choices) accepts += (accepts.empty() ? "" : "|") + c;
    std::string line = head + " " + o.help;
    std::string facts;
    if (!accepts.empty()) facts = accepts;
    if (!o.flag) facts += (facts.empty() ? "" : "; ") + (o.default_text.empty() ? std::string("required") : "default " + o.default_text);
    if (!facts.empty()) line += " [" + facts + "]";
    text += line + "\n";
  }
  return text;
}

Args::Args(std::string command, const std::vector<std::string>& argv, std::vector<OptionSpec> specs, const std::string& synopsis)
    : command_(std::move(command)), specs_(std::move(specs)) {
  std::set<std::string> known, flags;
  for (const OptionSpec& o : specs_) (o.flag ? flags : known).insert(o.name);
  for (const std::string& a : argv)
    if (a == "--help") throw HelpRequested(synopsis + describe_options(specs_), true);
  parse(argv, known, flags);
}

const OptionSpec* Args::declared(const std::string& name) const {
  if (specs_.empty()) return nullptr;
  for (const OptionSpec& o : specs_)
    if (o.name == name) return &o;
  throw std::logic_error(command_ + ": --" + name + " is read but not declared");
}

void Args::parse(const std::vector<std::string>& argv, const std::set<std::string>& known, const std::set<std::string>& flags) {
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
  (void)declared(name);
  auto it = values_.find(name);
  if (it != values_.end()) return it->second;
  if (fallback) return *fallback;
  fail(name, "is required");
}

std::int64_t Args::integer(const std::string& name, std::int64_t lo, std::int64_t hi,
                           std::optional<std::int64_t> fallback) const {
  if (const OptionSpec* o = declared(name);
      o && (!o->range || o->range->first != static_cast<double>(lo) || o->range->second != static_cast<double>(hi)))
    throw std::logic_error(command_ + ": --" + name + " is read with the range [" + std::to_string(lo) + ", " + std::to_string(hi) +
                           "], not the one it is declared with");
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
  if (const OptionSpec* o = declared(name); o && (!o->range || o->range->first != lo || o->range->second != hi))
    throw std::logic_error(command_ + ": --" + name + " is read with the range [" + std::to_string(lo) + ", " + std::to_string(hi) +
                           "], not the one it is declared with");
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
  if (const OptionSpec* o = declared(name); o && o->choices != allowed)
    throw std::logic_error(command_ + ": --" + name + " is read with other choices than it is declared with");
  const std::string v = str(name, fallback);
  for (const auto& a : allowed)
    if (a == v) return v;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : "|") + a;
  fail(name, "expected one of " + list + ", got '" + v + "'");
}

}  // namespace engine::core
