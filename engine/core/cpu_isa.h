#pragma once
// Which x86-64 instruction sets the engine's hand-dispatched code may use.
//
// Every fast kernel is chosen at run time from one ladder of levels, each a
// superset of the one below. The effective level is the lower of what the
// CPU (and the OS) allow and a cap read once from the environment, so one
// switch makes an AVX-512 machine run every kernel, its libraries included
// (Embree, oneDNN through the module that uses it), as an AVX2 machine would.
// The cap's variable is ENGINE_MAX_ISA unless the product that builds the
// engine names another (ENGINE_MAX_ISA_VARIABLE, a compile definition).
#include <optional>
#include <string>
#include <string_view>

namespace engine::cpu {

enum class Isa : int {
  Scalar = 0,  // the x86-64 baseline (SSE2): every kernel has a portable version
  Avx2 = 1,    // x86-64-v3: AVX2, FMA, F16C, BMI1/2 - what players' CPUs have
  Avx512 = 2,  // x86-64-v4: AVX-512 F, BW, CD, DQ, VL (BF16 is asked for apart: avx512_bf16())
  Amx = 3,     // AMX-TILE and AMX-BF16, with Linux's permission to use the tile state
};

const char* isa_name(Isa isa);
// "scalar", "avx2", "avx512" or "amx"; nothing for anything else.
std::optional<Isa> parse_isa(std::string_view name);

// The highest level this CPU and OS support, whatever the cap.
Isa detected_isa();
// The cap from the environment variable (max_isa_variable()); Amx (no cap)
// when it is unset. Throws std::runtime_error naming the variable and the
// value when the value is not a level's name.
Isa isa_cap();
const char* max_isa_variable();
// min(detected_isa(), isa_cap()): what the dispatchers use.
Isa effective_isa();
bool isa_enabled(Isa isa);
// AVX-512 BF16 (vdpbf16ps) where the AVX-512 level is enabled.
bool avx512_bf16();

// A line for benchmark output: the CPU's model name, what it supports and
// what is in effect, e.g. "Intel(R) Xeon(R) ... (supports amx, running avx2:
// capped by TRANSGI_MAX_ISA)".
std::string isa_summary();
std::string cpu_model_name();

// Picks one of three builds of a kernel: the highest the effective level allows.
template <class Fn>
Fn select(Fn scalar, Fn avx2, Fn avx512) {
  if (isa_enabled(Isa::Avx512)) return avx512;
  if (isa_enabled(Isa::Avx2)) return avx2;
  return scalar;
}

}  // namespace engine::cpu

// A kernel compiled once per level and dispatched through select(): write
// the body once as `ENGINE_INLINE_BODY ret name_body params`, then
// ENGINE_ISA_DISPATCH(ret, name, params, args) defines `ret name params`,
// which calls the body's scalar, x86-64-v3 or x86-64-v4 build, chosen once.
// GCC's target_clones does the same, but its choice cannot be capped.
#define ENGINE_INLINE_BODY inline __attribute__((always_inline))
#define ENGINE_ISA_DISPATCH(ret, name, params, args)                                            \
  ret name##_scalar params { return name##_body args; }                                         \
  __attribute__((target("arch=x86-64-v3"))) ret name##_avx2 params { return name##_body args; }   \
  __attribute__((target("arch=x86-64-v4"))) ret name##_avx512 params { return name##_body args; } \
  ret name params {                                                                             \
    static const auto chosen = engine::cpu::select(&name##_scalar, &name##_avx2, &name##_avx512); \
    return chosen args;                                                                         \
  }
