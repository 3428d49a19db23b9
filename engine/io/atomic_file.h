#pragma once
// Writes a file so that readers only ever see the old content or the complete
// new content: write to a temporary sibling, fsync it, rename over the target,
// then fsync the directory. A crash or error mid-write leaves the old file.
#include <cstddef>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>

namespace engine::io {

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Throws IoError naming the path and the failing step.
void write_file_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes);

}  // namespace engine::io
