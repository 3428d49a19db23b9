#pragma once
// Small helpers for the harness's text outputs (reports, tables, CSV).
#include <cstdio>
#include <filesystem>
#include <span>
#include <string>

#include "engine/io/atomic_file.h"

namespace transgi::eval {

inline void write_text(const std::filesystem::path& path, const std::string& text) {
  engine::io::write_file_atomically(path, std::as_bytes(std::span(text.data(), text.size())));
}

// printf-style formatting of one number.
inline std::string fmt(const char* format, double v) {
  char b[64];
  std::snprintf(b, sizeof(b), format, v);
  return b;
}

}  // namespace transgi::eval
