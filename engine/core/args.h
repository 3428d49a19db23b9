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
#include <utility>
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
  // complete: what() is the whole help (the command declared its options
  // with OptionSpec), not only the list of names to print after a usage line.
  explicit HelpRequested(const std::string& text, bool complete = false) : std::runtime_error(text), complete_(complete) {}
  [[nodiscard]] bool complete() const { return complete_; }

 private:
  bool complete_ = false;
};

// One option of a command, declared once: the parser checks every read of it
// against this declaration, and `--help` and the README's synopsis are made
// from it, so the three cannot drift apart.
struct OptionSpec {
  std::string name;          // without the leading "--"
  std::string value;         // what the value stands for ("N", "PATH", ...); empty for a flag
  std::string default_text;  // what applies when it is not given; empty: required
  std::string help;          // one line; a tuning knob says "higher = ... at the cost of ..."
  // What it accepts: a closed range, or a list of words; neither = any text.
  std::optional<std::pair<double, double>> range;
  std::vector<std::string> choices;
  bool flag = false;
};

// The options as `--help` prints them: one line each, the value, its range
// or choices, its default and the help.
std::string describe_options(const std::vector<OptionSpec>& specs);

class Args {
 public:
  // From declarations: --help anywhere throws HelpRequested with
  // `synopsis` and describe_options(specs); a read whose range or choices
  // differ from the declaration, or of an undeclared option, is a
  // programming error (std::logic_error).
  Args(std::string command, const std::vector<std::string>& argv, std::vector<OptionSpec> specs, const std::string& synopsis);
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
  void parse(const std::vector<std::string>& argv, const std::set<std::string>& known, const std::set<std::string>& flags);
  // The declaration of `name` when the options were declared (nullptr
  // otherwise); throws std::logic_error for an undeclared one.
  const OptionSpec* declared(const std::string& name) const;
  std::string command_;
  std::vector<OptionSpec> specs_;
  std::map<std::string, std::string> values_;
  std::set<std::string> set_flags_;
  std::vector<std::string> positional_;
};

}  // namespace engine::core
