#pragma once
// Row-major single-precision GEMM, C = alpha op(A) op(B) + beta C, behind one
// interface with two backends: a plain reference loop (the oracle) and
// oneDNN's sgemm (JIT-dispatched to AVX-512 or AVX2 at run time).
#include <cstdint>

namespace transgi::model {

enum class GemmBackend { Reference, OneDnn };

void gemm(GemmBackend backend, bool trans_a, bool trans_b, std::int64_t m, std::int64_t n, std::int64_t k, float alpha,
          const float* a, std::int64_t lda, const float* b, std::int64_t ldb, float beta, float* c, std::int64_t ldc);

// The fastest backend available on this machine.
GemmBackend default_gemm_backend();

}  // namespace transgi::model
