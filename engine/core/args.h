#pragma once
// Command-line options: "--name value" pairs and "--flag" switches, each
// declared with its type and range so that bad input gets a one-line reason
// naming the option. Shared by every tool and game built on the engine.
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace engine::core {

class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Thrown by Args when the command line asks for --help and the command
// declares no --help of its own: what() lists every option it accepts, from
// the same declarations that parse them (so it cannot drift from them).
class HelpRequested : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Args {
 public:
  // `known` lists accepted options with a value; `flags` those without.
  // --help anywhere throws HelpRequested unless "help" is one of them.
  Args(std::string command, const std::vector<std::string>& argv, std::set<std::string> known,
       std::set<std::string> flags = {});

  [[nodiscard]] bool has(const std::string& name) const { return values_.contains(name) || set_flags_.contains(name); }
  [[nodiscard]] std::string str(const std::string& name, std::optional<std::string> fallback = std::nullopt) const;
  [[nodiscard]] std::int64_t integer(const std::string& name, std::int64_t lo, std::int64_t hi,
                                     std::optional<std::int64_t> fallback = std::nullopt) const;
  [[nodiscard]] double number(const std::string& name, double lo, double hi, std::optional<double> fallback = std::nullopt) const;
  [[nodiscard]] std::string choice(const std::string& name, const std::vector<std::string>& allowed,
                                   std::optional<std::string> fallback = std::nullopt) const;
  [[nodiscard]] const std::vector<std::string>& positional() const { return positional_; }

 private:
  [[noreturn]] void fail(const std::string& name, const std::string& why) const;
  std::string command_;
  std::map<std::string, std::string> values_;
  std::set<std::string> set_flags_;
  std::vector<std::string> positional_;
};

}  // namespace engine::core
