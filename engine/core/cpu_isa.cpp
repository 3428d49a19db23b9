#include "engine/core/cpu_isa.h"

#include <cpuid.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

#ifndef ENGINE_MAX_ISA_VARIABLE
#define ENGINE_MAX_ISA_VARIABLE "ENGINE_MAX_ISA"
#endif

namespace engine::cpu {

namespace {

constexpr Isa kLevels[] = {Isa::Scalar, Isa::Avx2, Isa::Avx512, Isa::Amx};

bool cpuid_bit(unsigned leaf, unsigned subleaf, int reg, int bit) {
  unsigned r[4] = {0, 0, 0, 0};
  if (!__get_cpuid_count(leaf, subleaf, &r[0], &r[1], &r[2], &r[3])) return false;
  return (r[reg] >> bit) & 1u;
}
enum { kEax = 0, kEbx = 1, kEcx = 2, kEdx = 3 };

// CPUID rather than __builtin_cpu_supports for F16C and AMX, which clang 14
// (the fuzz preset's compiler) does not know.
bool has_x86_64_v3() {
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
         __builtin_cpu_supports("bmi2") && cpuid_bit(1, 0, kEcx, 29 /* F16C */);
}

bool has_x86_64_v4() {
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
         __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512vl");
}

bool has_avx512_bf16() { return cpuid_bit(7, 1, kEax, 5); }

// AMX-TILE and AMX-BF16 in CPUID, and Linux's permission to use the tile
// state: without ARCH_REQ_XCOMP_PERM the first tile instruction is SIGILL.
bool amx_usable() {
  if (!cpuid_bit(7, 0, kEdx, 24) || !cpuid_bit(7, 0, kEdx, 22)) return false;
#ifdef SYS_arch_prctl
  constexpr long kArchReqXcompPerm = 0x1023, kXfeatureXtiledata = 18;
  return syscall(SYS_arch_prctl, kArchReqXcompPerm, kXfeatureXtiledata) == 0;
#else
  return false;
#endif
}

Isa detect() {
  if (!has_x86_64_v3()) return Isa::Scalar;
  if (!has_x86_64_v4()) return Isa::Avx2;
  // The AMX kernels feed their tiles with AVX-512 BF16 code.
  if (has_avx512_bf16() && amx_usable()) return Isa::Amx;
  return Isa::Avx512;
}

Isa read_cap() {
  const char* v = std::getenv(ENGINE_MAX_ISA_VARIABLE);
  if (v == nullptr || *v == '\0') return Isa::Amx;
  if (const auto isa = parse_isa(v)) return *isa;
  throw std::runtime_error(std::string(ENGINE_MAX_ISA_VARIABLE) + ": expected scalar, avx2, avx512 or amx, got '" + v +
                           "'");
}

}  // namespace

const char* isa_name(Isa isa) {
  switch (isa) {
    case Isa::Scalar: return "scalar";
    case Isa::Avx2: return "avx2";
    case Isa::Avx512: return "avx512";
    case Isa::Amx: return "amx";
  }
  return "?";
}

std::optional<Isa> parse_isa(std::string_view name) {
  for (Isa isa : kLevels)
    if (name == isa_name(isa)) return isa;
  return std::nullopt;
}

Isa detected_isa() {
  static const Isa isa = detect();
  return isa;
}

Isa isa_cap() {
  static const Isa cap = read_cap();
  return cap;
}

const char* max_isa_variable() { return ENGINE_MAX_ISA_VARIABLE; }

Isa effective_isa() { return std::min(detected_isa(), isa_cap()); }

bool isa_enabled(Isa isa) { return isa <= effective_isa(); }

bool avx512_bf16() {
  static const bool has = has_avx512_bf16();
  return isa_enabled(Isa::Avx512) && has;
}

std::string cpu_model_name() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) return line.substr(line.find_first_not_of(" \t", colon + 1));
    }
  return "unknown CPU";
}

std::string isa_summary() {
  std::string s = cpu_model_name() + " (supports " + isa_name(detected_isa());
  if (detected_isa() >= Isa::Avx512 && !has_avx512_bf16()) s += " without bf16";
  s += std::string(", running ") + isa_name(effective_isa());
  if (effective_isa() < detected_isa()) s += std::string(": capped by ") + ENGINE_MAX_ISA_VARIABLE;
  return s + ")";
}

}  // namespace engine::cpu
