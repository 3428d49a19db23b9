#include "engine/core/install_paths.h"

#include <system_error>

namespace engine::core {

std::filesystem::path executable_dir() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::filesystem::path() : exe.parent_path();
}

std::optional<std::filesystem::path> beside_executable(const std::filesystem::path& relative) {
  const std::filesystem::path dir = executable_dir();
  if (dir.empty()) return std::nullopt;
  std::error_code ec;
  const std::filesystem::path p = (dir / relative).lexically_normal();
  if (!std::filesystem::exists(p, ec)) return std::nullopt;
  return p;
}

}  // namespace engine::core
