#include "engine/core/install_paths.h"

#include <system_error>
#include <vector>

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

std::optional<std::filesystem::path> installed_twin(const std::filesystem::path& folder, const std::filesystem::path& installed,
                                                    const std::filesystem::path& other) {
  std::filesystem::path prefix = folder.lexically_normal();
  if (prefix.filename().empty()) prefix = prefix.parent_path();  // a trailing slash
  std::vector<std::filesystem::path> parts;
  for (const std::filesystem::path& part : installed.lexically_normal())
    if (!part.empty()) parts.push_back(part);
  // Strip `installed` off the end of `folder`, last part first.
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) {
    if (prefix.filename() != *it) return std::nullopt;
    prefix = prefix.parent_path();
  }
  std::error_code ec;
  const std::filesystem::path twin = prefix / other;
  if (!std::filesystem::is_directory(twin, ec)) return std::nullopt;
  return twin;
}

}  // namespace engine::core
