#include "eval/machine_peak.h"

// GCC 12's _mm512_reduce_add_ps reads an undefined vector; the warning is
// about the header, not this code.
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>

#include <tbb/task_arena.h>

#include "engine/core/cpu_isa.h"
#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "shading/fused_decoder.h"
#include "shading/fused_kernels.h"

namespace transgi::eval {

namespace {

using Clock = std::chrono::steady_clock;

// 24 independent chains cover the FMA latency at two issues per cycle; the
// empty asm keeps the compiler from folding them.
__attribute__((target("avx512f,avx512bf16"))) double bf16_loop(long long reps) {
  __m512 acc[24];
  for (int i = 0; i < 24; ++i) acc[i] = _mm512_set1_ps(static_cast<float>(i));
  __m512bh a = (__m512bh)_mm512_set1_epi32(0x3f803f80);
  const __m512bh b = (__m512bh)_mm512_set1_epi32(0x00010001);
  for (long long r = 0; r < reps; ++r) {
    asm volatile("" : "+v"(a));
#pragma GCC unroll 24
    for (int i = 0; i < 24; ++i) acc[i] = _mm512_dpbf16_ps(acc[i], a, b);
  }
  __m512 s = acc[0];
  for (int i = 1; i < 24; ++i) s = _mm512_add_ps(s, acc[i]);
  return static_cast<double>(_mm512_reduce_add_ps(s));
}

__attribute__((target("avx512f"))) double fp32_loop_avx512(long long reps) {
  __m512 acc[24];
  for (int i = 0; i < 24; ++i) acc[i] = _mm512_set1_ps(static_cast<float>(i));
  __m512 a = _mm512_set1_ps(0.999f);
  const __m512 b = _mm512_set1_ps(1e-3f);
  for (long long r = 0; r < reps; ++r) {
    asm volatile("" : "+v"(a));
#pragma GCC unroll 24
    for (int i = 0; i < 24; ++i) acc[i] = _mm512_fmadd_ps(acc[i], a, b);
  }
  __m512 s = acc[0];
  for (int i = 1; i < 24; ++i) s = _mm512_add_ps(s, acc[i]);
  return static_cast<double>(_mm512_reduce_add_ps(s));
}

__attribute__((target("avx2,fma"))) double fp32_loop_avx2(long long reps) {
  __m256 acc[12];
  for (int i = 0; i < 12; ++i) acc[i] = _mm256_set1_ps(static_cast<float>(i));
  __m256 a = _mm256_set1_ps(0.999f);
  const __m256 b = _mm256_set1_ps(1e-3f);
  for (long long r = 0; r < reps; ++r) {
    asm volatile("" : "+x"(a));
#pragma GCC unroll 12
    for (int i = 0; i < 12; ++i) acc[i] = _mm256_fmadd_ps(acc[i], a, b);
  }
  float out[8];
  __m256 s = acc[0];
  for (int i = 1; i < 12; ++i) s = _mm256_add_ps(s, acc[i]);
  _mm256_storeu_ps(out, s);
  return static_cast<double>(out[0]);
}

// FLOP/s of `loop` run on every worker: a calibration run sizes 16 equal
// chunks to fill about `seconds`, which the job system spreads over its threads.
template <class Loop>
double all_threads_gflops(Loop loop, double flop_per_rep, double seconds) {
  volatile double sink = 0;
  long long reps = 1 << 12;
  auto t0 = Clock::now();
  sink = loop(reps);
  const double per_rep = std::chrono::duration<double>(Clock::now() - t0).count() / static_cast<double>(reps);
  constexpr int kChunks = 16;
  reps = std::max(1LL, static_cast<long long>(seconds / per_rep / kChunks * tbb::this_task_arena::max_concurrency()));
  t0 = Clock::now();
  engine::jobs::parallel_for(0, kChunks, 1, [&](int b, int e) {
    for (int c = b; c < e; ++c) sink = loop(reps);
  });
  const double s = std::chrono::duration<double>(Clock::now() - t0).count();
  (void)sink;
  return static_cast<double>(reps) * kChunks * flop_per_rep / s * 1e-9;
}

}  // namespace

double bf16_peak_loop(long long reps) { return bf16_loop(reps); }
double amx_peak_loop(long long reps) { return shading::detail::amx_peak_loop(reps); }

MachinePeak measure_machine_peak(const engine::rt::RtScene& scene, double seconds) {
  MachinePeak p;
  if (shading::cpu_supports(shading::FusedIsa::Avx512Bf16))
    p.bf16_gflops = all_threads_gflops(bf16_loop, 24.0 * 64.0, seconds / 3);
  if (shading::cpu_supports(shading::FusedIsa::Amx))
    p.amx_gflops = all_threads_gflops(shading::detail::amx_peak_loop, 4.0 * 16384.0, seconds / 3);
  if (engine::cpu::isa_enabled(engine::cpu::Isa::Avx512))
    p.fp32_gflops = all_threads_gflops(fp32_loop_avx512, 24.0 * 32.0, seconds / 3);
  else if (engine::cpu::isa_enabled(engine::cpu::Isa::Avx2))
    p.fp32_gflops = all_threads_gflops(fp32_loop_avx2, 12.0 * 16.0, seconds / 3);
  // Incoherent rays: random origins inside the scene's bounds, random directions.
  constexpr int kRays = 1 << 17;
  const glm::vec3 lo = scene.bounds_min(), hi = scene.bounds_max();
  const auto t0 = Clock::now();
  std::atomic<long long> hits{0};
  engine::jobs::parallel_for(0, kRays, 1024, [&](int b, int e) {
    long long h = 0;
    for (int i = b; i < e; ++i) {
      engine::math::Pcg32 rng = engine::math::make_rng(17, static_cast<std::uint64_t>(i), 0);
      engine::rt::Ray ray;
      ray.origin = lo + (hi - lo) * glm::vec3{rng.next_float(), rng.next_float(), rng.next_float()};
      ray.direction = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
      engine::rt::Hit hit;
      h += scene.intersect(ray, hit) ? 1 : 0;
    }
    hits += h;
  });
  p.incoherent_mrays = kRays / std::chrono::duration<double>(Clock::now() - t0).count() * 1e-6;
  return p;
}

}  // namespace transgi::eval
