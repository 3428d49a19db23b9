#include "engine/gpu/shader_compiler.h"

#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include "engine/gpu/gpu_error.h"

namespace engine::gpu {
namespace {

namespace fs = std::filesystem;

// glslang keeps global tables: initialise once, and serialise compiles
// (its symbol-table setup is not documented as thread-safe).
std::mutex& glslang_mutex() {
  static std::mutex m;
  static std::once_flag once;
  std::call_once(once, [] { glslang::InitializeProcess(); });
  return m;
}

bool read_text(const fs::path& path, std::string& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  out = s.str();
  return true;
}

// Resolves "x.h" against the including file's folder, then the include dirs.
class Includer : public glslang::TShader::Includer {
 public:
  Includer(fs::path main_dir, std::vector<fs::path> dirs) : main_dir_(std::move(main_dir)), dirs_(std::move(dirs)) {}

  IncludeResult* includeLocal(const char* header, const char* includer, size_t) override {
    std::vector<fs::path> candidates;
    const fs::path from = (includer && *includer) ? fs::path(includer).parent_path() : main_dir_;
    if (!from.empty()) candidates.push_back(from / header);
    for (const auto& d : dirs_) candidates.push_back(d / header);
    for (const auto& c : candidates) {
      auto text = std::make_unique<std::string>();
      if (read_text(c, *text)) {
        auto* r = new IncludeResult(c.string(), text->data(), text->size(), text.get());
        text.release();
        return r;
      }
    }
    return nullptr;  // glslang reports "cannot find include file" at the line
  }
  IncludeResult* includeSystem(const char* header, const char* includer, size_t depth) override {
    return includeLocal(header, includer, depth);
  }
  void releaseInclude(IncludeResult* r) override {
    if (!r) return;
    delete static_cast<std::string*>(r->userData);
    delete r;
  }

 private:
  fs::path main_dir_;
  std::vector<fs::path> dirs_;
};

EShLanguage glslang_stage(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::Vertex: return EShLangVertex;
    case ShaderStage::Fragment: return EShLangFragment;
    case ShaderStage::Compute: break;
  }
  return EShLangCompute;
}

std::vector<std::uint32_t> compile(std::string_view source, const std::string& name, const fs::path& main_dir,
                                   const ShaderCompileOptions& options, ShaderStage stage = ShaderStage::Compute) {
  const EShLanguage language = glslang_stage(stage);
  std::lock_guard lock(glslang_mutex());
  std::string preamble;
  for (const auto& d : options.defines) preamble += "#define " + d.name + " " + d.value + "\n";

  glslang::TShader shader(language);
  const char* text = source.data();
  const int length = static_cast<int>(source.size());
  const char* names = name.c_str();
  shader.setStringsWithLengthsAndNames(&text, &length, &names, 1);
  shader.setPreamble(preamble.c_str());
  shader.setEnvInput(glslang::EShSourceGlsl, language, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
  Includer includer(main_dir, options.include_dirs);
  const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
  if (!shader.parse(GetDefaultResources(), 460, false, messages, includer))
    throw GpuError(format_glslang_log(shader.getInfoLog(), name));

  glslang::TProgram program;
  program.addShader(&shader);
  if (!program.link(messages)) throw GpuError(format_glslang_log(program.getInfoLog(), name));

  std::vector<std::uint32_t> spirv;
  spv::SpvBuildLogger logger;
  glslang::SpvOptions spv_options;
  spv_options.validate = true;
  glslang::GlslangToSpv(*program.getIntermediate(language), spirv, &logger, &spv_options);
  const std::string extra = logger.getAllMessages();
  if (spirv.empty()) throw GpuError(name + ": SPIR-V generation failed: " + extra);
  return spirv;
}

}  // namespace

std::string format_glslang_log(std::string_view log, const std::string& main_name) {
  // glslang writes "ERROR: <name>:<line>: '<token>' : <text>"; keep every
  // diagnostic line, reworded as "<name>:<line>: error: <token> : <text>".
  std::string out;
  std::istringstream lines{std::string(log)};
  for (std::string line; std::getline(lines, line);) {
    if (line.empty()) continue;
    std::string severity;
    for (const char* prefix : {"ERROR: ", "WARNING: "}) {
      if (line.rfind(prefix, 0) == 0) {
        severity = prefix[0] == 'E' ? "error" : "warning";
        line = line.substr(std::string_view(prefix).size());
      }
    }
    if (severity.empty()) continue;
    if (line.find("compilation terminated") != std::string::npos) continue;  // follows the real error
    // "<name>:<line>: rest"; a "0:<line>" name is the main file.
    const auto c1 = line.find(':');
    const auto c2 = c1 == std::string::npos ? std::string::npos : line.find(':', c1 + 1);
    if (c2 == std::string::npos) {
      if (line.find("compilation errors") != std::string::npos) continue;  // the summary glslang adds
      out += main_name + ": " + severity + ": " + line + "\n";
      continue;
    }
    std::string file = line.substr(0, c1);
    if (file == "0" || file.empty()) file = main_name;
    out += file + ":" + line.substr(c1 + 1, c2 - c1 - 1) + ": " + severity + ":" + line.substr(c2 + 1) + "\n";
  }
  if (out.empty()) out = main_name + ": " + std::string(log);
  if (!out.empty() && out.back() == '\n') out.pop_back();
  return out;
}

std::vector<std::uint32_t> compile_compute_shader(const fs::path& file, const ShaderCompileOptions& options) {
  std::string source;
  if (!read_text(file, source)) throw GpuError(file.string() + ": cannot read the shader");
  return compile(source, file.string(), file.parent_path(), options);
}

ShaderStage shader_stage_of(const fs::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".comp") return ShaderStage::Compute;
  if (ext == ".vert") return ShaderStage::Vertex;
  if (ext == ".frag") return ShaderStage::Fragment;
  throw GpuError(file.string() + ": not a shader stage glslang names (.comp, .vert, .frag)");
}

std::vector<std::uint32_t> compile_shader(const fs::path& file, const ShaderCompileOptions& options) {
  const ShaderStage stage = shader_stage_of(file);
  std::string source;
  if (!read_text(file, source)) throw GpuError(file.string() + ": cannot read the shader");
  return compile(source, file.string(), file.parent_path(), options, stage);
}

std::vector<std::uint32_t> compile_compute_source(std::string_view source, const std::string& name,
                                                  const ShaderCompileOptions& options) {
  return compile(source, name, fs::path(), options);
}

}  // namespace engine::gpu
