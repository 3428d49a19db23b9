#pragma once
// Row-major GEMM, C = alpha op(A) op(B) + beta C on float arrays, behind one
// interface with three backends:
//  - Reference: a plain loop with double accumulation (the test oracle);
//  - OneDnn: oneDNN's f32 sgemm, JIT-dispatched to AVX-512 or AVX2;
//  - OneDnnBf16: A and B rounded to bfloat16 and multiplied by oneDNN's
//    matmul primitive with f32 accumulation (AVX-512 BF16 instructions where
//    the CPU has them). Half the bytes per operand, ~3 significant digits.
#include <cstdint>
#include <string>

namespace transgi::model {

enum class GemmBackend { Reference, OneDnn, OneDnnBf16 };

void gemm(GemmBackend backend, bool trans_a, bool trans_b, std::int64_t m, std::int64_t n, std::int64_t k, float alpha,
          const float* a, std::int64_t lda, const float* b, std::int64_t ldb, float beta, float* c, std::int64_t ldc);

// OneDnn (f32). Measured on the 2-core AVX-512 BF16 machine
// (docs/benchmarks.md): the bf16 path is slower for these small GEMMs
// (forward 6.1 vs 4.8 ms at batch 2048) because rounding the operands and
// the epilogue cost more than the bf16 instructions save. The environment
// variable TRANSGI_GEMM=f32|bf16|reference overrides the choice.
GemmBackend default_gemm_backend();
// Whether oneDNN runs a bf16 matmul at the effective ISA (TRANSGI_MAX_ISA):
// AVX-512 (with or without BF16) yes, AVX2 no. OneDnnBf16 throws where not.
bool bf16_gemm_available();
const char* gemm_backend_name(GemmBackend backend);
// The instruction set oneDNN's kernels run with, after TRANSGI_MAX_ISA.
std::string onednn_isa_name();
// How many threads oneDNN's GEMMs use (its OpenMP pool); 0 = one per core.
// The OpenMP runtime reads OMP_NUM_THREADS once, when the program loads, so a
// command's --threads (or a bake rank's share of its machine) is set here.
void set_gemm_threads(int threads);
// The calling thread's oneDNN products on `threads` threads until the scope
// ends, then on as many as before (OpenMP keeps the setting per thread).
class GemmThreadsScope {
 public:
  explicit GemmThreadsScope(int threads);
  ~GemmThreadsScope();
  GemmThreadsScope(const GemmThreadsScope&) = delete;
  GemmThreadsScope& operator=(const GemmThreadsScope&) = delete;

 private:
  int before_;
};

}  // namespace transgi::model
