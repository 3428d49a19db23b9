// The instruction-set ladder (engine/core/cpu_isa.h): names, the cap, and the
// dispatcher's choice. CTest runs the ISA-dependent suites again with the cap
// at avx2 and at scalar (labels isa_avx2, isa_scalar), so on an AVX-512
// machine these check that the cap reaches what they dispatch.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "engine/core/cpu_isa.h"

using namespace engine::cpu;

TEST(CpuIsa, NamesRoundTripAndUnknownNamesAreRejected) {
  for (Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512, Isa::Amx}) EXPECT_EQ(parse_isa(isa_name(isa)), isa);
  EXPECT_FALSE(parse_isa("avx3").has_value());
  EXPECT_FALSE(parse_isa("AVX2").has_value());
  EXPECT_FALSE(parse_isa("").has_value());
}

TEST(CpuIsa, TheEffectiveLevelIsTheCpusCappedByTheEnvironment) {
  const char* v = std::getenv(max_isa_variable());
  const Isa cap = v != nullptr && *v != '\0' ? parse_isa(v).value() : Isa::Amx;
  EXPECT_EQ(isa_cap(), cap);
  EXPECT_EQ(effective_isa(), std::min(detected_isa(), cap));
  for (Isa isa : {Isa::Scalar, Isa::Avx2, Isa::Avx512, Isa::Amx}) EXPECT_EQ(isa_enabled(isa), isa <= effective_isa());
  if (!isa_enabled(Isa::Avx512)) {
    EXPECT_FALSE(avx512_bf16());
  }
  std::printf("%s\n", isa_summary().c_str());
}

TEST(CpuIsa, SelectPicksTheHighestEnabledBuild) {
  const int chosen = select(0, 1, 2);
  EXPECT_EQ(chosen, std::min(static_cast<int>(effective_isa()), 2));
}

namespace {
ENGINE_INLINE_BODY float dot8_body(const float* a, const float* b) {
  float s = 0;
  for (int i = 0; i < 8; ++i) s += a[i] * b[i];
  return s;
}
ENGINE_ISA_DISPATCH(float, dot8, (const float* a, const float* b), (a, b))
}  // namespace

TEST(CpuIsa, EveryBuildOfADispatchedKernelGivesTheSameAnswer) {
  const float a[8] = {1, 2, 3, 4, 5, 6, 7, 8}, b[8] = {0.5f, -1, 2, 0.25f, 3, -2, 1, 0.125f};
  const float expected = 0.5f - 2 + 6 + 1 + 15 - 12 + 7 + 1;
  EXPECT_EQ(dot8_scalar(a, b), expected);
  if (isa_enabled(Isa::Avx2)) {
    EXPECT_EQ(dot8_avx2(a, b), expected);
  }
  if (isa_enabled(Isa::Avx512)) {
    EXPECT_EQ(dot8_avx512(a, b), expected);
  }
  EXPECT_EQ(dot8(a, b), expected);
}
