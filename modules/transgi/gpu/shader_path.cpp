#include "gpu/shader_path.h"

#include <cstdlib>

namespace transgi::gpu {

std::filesystem::path shader_dir() {
  if (const char* env = std::getenv("TRANSGI_SHADER_DIR"); env && *env) return env;
  return TRANSGI_SOURCE_SHADER_DIR;
}

std::vector<std::uint32_t> compile_module_shader(const char* name, std::vector<engine::gpu::ShaderDefine> defines) {
  const auto dir = shader_dir();
  engine::gpu::ShaderCompileOptions options;
  options.include_dirs.push_back(dir);
  options.defines = std::move(defines);
  return engine::gpu::compile_compute_shader(dir / name, options);
}

}  // namespace transgi::gpu
