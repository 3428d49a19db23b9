#pragma once
// The transgi tool's command-line options: the engine's parser, under the
// names the commands use, plus how a report records its command line.
#include <string>
#include <vector>

#include "engine/core/args.h"

namespace transgi::cli {

using engine::core::Args;
using engine::core::UsageError;

// "transgi <command> <args...>", for reports that record how they were made.
std::string command_line(const std::string& command, const std::vector<std::string>& argv);

}  // namespace transgi::cli
