#pragma once
// GLSL 4.60 shaders (compute, and the vertex and fragment stages of a raster
// pass) to SPIR-V with glslang's C++ API, at run time.
// Run time rather than only at build time so that a shader can be edited and
// reloaded while the engine runs (shaders/README.md); the build also compiles
// every shader once with the same code (the glsl_check tool), so a GLSL error
// fails the build as well as the load.
//
// Errors come back as GpuError with one "file:line: message" line per
// diagnostic, the form editors and CI logs link to; lines in an #included
// header name that header.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace engine::gpu {

struct ShaderDefine {
  std::string name;
  std::string value;
};

struct ShaderCompileOptions {
  // Where `#include "x.h"` looks after the including file's own folder.
  std::vector<std::filesystem::path> include_dirs;
  std::vector<ShaderDefine> defines;
};

enum class ShaderStage { Compute, Vertex, Fragment };

// The stage a file holds, by its extension as glslang's tools name them:
// .comp, .vert, .frag. Throws GpuError for any other.
ShaderStage shader_stage_of(const std::filesystem::path& file);

// Compiles one compute shader file. Throws GpuError (unreadable file,
// compile or link errors, each as "file:line: message").
std::vector<std::uint32_t> compile_compute_shader(const std::filesystem::path& file,
                                                  const ShaderCompileOptions& options = {});
// Any stage, by the file's extension (shader_stage_of).
std::vector<std::uint32_t> compile_shader(const std::filesystem::path& file, const ShaderCompileOptions& options = {});

// The same for source text; `name` stands for the file in messages, and
// includes are looked up in options.include_dirs only.
std::vector<std::uint32_t> compile_compute_source(std::string_view source, const std::string& name,
                                                  const ShaderCompileOptions& options = {});

// glslang's info log turned into "file:line: message" lines (exposed for the
// test of that format).
std::string format_glslang_log(std::string_view log, const std::string& main_name);

}  // namespace engine::gpu
