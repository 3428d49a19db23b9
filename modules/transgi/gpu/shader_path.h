#pragma once
// Where the module's GLSL lives at run time: $TRANSGI_SHADER_DIR when set
// (edit and reload without rebuilding), else the source tree's shaders/
// folder that this build was configured from.
#include <filesystem>

#include "engine/gpu/shader_compiler.h"

namespace transgi::gpu {

std::filesystem::path shader_dir();
// Compiles shaders/<name> with shaders/ on the include path.
std::vector<std::uint32_t> compile_module_shader(const char* name, std::vector<engine::gpu::ShaderDefine> defines = {});

}  // namespace transgi::gpu
