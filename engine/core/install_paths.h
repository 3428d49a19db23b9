#pragma once
// Where an installed program finds what was installed beside it: paths
// relative to the running executable's folder, so an installed tree can be
// moved (cmake --install --prefix anywhere, a Debian package under /usr).
#include <filesystem>
#include <optional>

namespace engine::core {

// The folder of the running executable (/proc/self/exe); empty where it
// cannot be read.
std::filesystem::path executable_dir();

// executable_dir() / relative, if that exists; else nothing.
std::optional<std::filesystem::path> beside_executable(const std::filesystem::path& relative);

// For a folder installed at PREFIX/installed (a relative path), its twin at
// PREFIX/other, if `folder` ends in `installed` and the twin exists: an
// installed shader folder's include folder, wherever the prefix now is.
std::optional<std::filesystem::path> installed_twin(const std::filesystem::path& folder, const std::filesystem::path& installed,
                                                    const std::filesystem::path& other);

}  // namespace engine::core
