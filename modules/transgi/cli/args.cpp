#include "cli/args.h"

namespace transgi::cli {

std::string command_line(const std::string& command, const std::vector<std::string>& argv) {
  std::string s = "transgi " + command;
  for (const auto& a : argv) s += " " + a;
  return s;
}

}  // namespace transgi::cli
