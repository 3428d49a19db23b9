// glsl_check FILE... [-I DIR]... [-D NAME=VALUE]...: compiles each shader (its stage by its extension) the way the
// engine does at run time and prints "file:line: error: ..." for each
// problem. The build runs it over shaders/, so a GLSL error fails the build.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "engine/gpu/gpu_error.h"
#include "engine/gpu/shader_compiler.h"

int main(int argc, char** argv) {
  engine::gpu::ShaderCompileOptions options;
  std::vector<const char*> files;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "-I") == 0 && i + 1 < argc) {
      options.include_dirs.emplace_back(argv[++i]);
    } else if (std::strcmp(argv[i], "-D") == 0 && i + 1 < argc) {
      const std::string define = argv[++i];
      const std::size_t eq = define.find('=');
      options.defines.push_back({define.substr(0, eq), eq == std::string::npos ? "1" : define.substr(eq + 1)});
    } else {
      files.push_back(argv[i]);
    }
  }
  int failed = 0;
  for (const char* f : files) {
    try {
      const auto spirv = engine::gpu::compile_shader(f, options);
      std::printf("glsl_check: %s: %zu SPIR-V words\n", f, spirv.size());
    } catch (const engine::gpu::GpuError& e) {
      std::fprintf(stderr, "%s\n", e.what());
      ++failed;
    }
  }
  return failed ? 1 : 0;
}
