#include "gpu/shader_path.h"

#include <cstdlib>
#include <exception>

#include "engine/core/install_paths.h"

namespace transgi::gpu {

std::filesystem::path shader_dir() {
  if (const char* env = std::getenv("TRANSGI_SHADER_DIR"); env && *env) return env;
  // An installed program: bin/ beside the installed shaders (the layout
  // cmake/TransGIInstall.cmake makes, named once in CMakeLists.txt).
  if (auto dir = engine::core::beside_executable(std::filesystem::path("..") / TRANSGI_INSTALLED_SHADER_DIR)) return *dir;
  return TRANSGI_SOURCE_SHADER_DIR;
}

std::vector<std::uint32_t> compile_module_shader(const char* name, std::vector<engine::gpu::ShaderDefine> defines) {
  const auto dir = shader_dir();
  engine::gpu::ShaderCompileOptions options;
  options.include_dirs.push_back(dir);
  // Installed, the headers the kernels share with C++ are with the C++
  // headers, not beside the kernels.
  if (auto shared = engine::core::installed_twin(dir, TRANSGI_INSTALLED_SHADER_DIR, TRANSGI_INSTALLED_SHADER_INCLUDE_DIR))
    options.include_dirs.push_back(*shared);
  options.defines = std::move(defines);
  return engine::gpu::compile_compute_shader(dir / name, options);
}

std::vector<std::string> check_module_shaders() {
  std::vector<std::string> errors;
  const auto dir = shader_dir();
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    if (entry.path().extension() != ".comp") continue;
    try {
      compile_module_shader(entry.path().filename().string().c_str());
    } catch (const std::exception& e) {
      errors.emplace_back(e.what());
    }
  }
  if (ec) errors.push_back(dir.string() + ": cannot list the shader folder: " + ec.message());
  return errors;
}

}  // namespace transgi::gpu
