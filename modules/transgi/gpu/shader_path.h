#pragma once
// Where the module's GLSL lives at run time: $TRANSGI_SHADER_DIR when set
// (edit and reload without rebuilding), else the source tree's shaders/
// folder that this build was configured from.
#include <filesystem>
#include <string>
#include <vector>

#include "engine/gpu/shader_compiler.h"

namespace transgi::gpu {

std::filesystem::path shader_dir();
// Compiles shaders/<name> with shaders/ on the include path.
std::vector<std::uint32_t> compile_module_shader(const char* name, std::vector<engine::gpu::ShaderDefine> defines = {});

// Compiles every shaders/*.comp as the kernels will; returns one
// "file:line: error: ..." block per shader that fails (empty = all good).
// The hot-reload path: check, then rebuild the kernels
// (TransGISettings::shader_generation) only if nothing failed.
std::vector<std::string> check_module_shaders();

}  // namespace transgi::gpu
