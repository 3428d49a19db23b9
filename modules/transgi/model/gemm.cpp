#include "model/gemm.h"

#include <omp.h>
#include <oneapi/dnnl/dnnl.h>
#include <oneapi/dnnl/dnnl_debug.h>

#include "engine/core/cpu_isa.h"

#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <vector>
#include <string>

namespace transgi::model {

namespace {

dnnl_cpu_isa_t onednn_isa(engine::cpu::Isa isa) {
  switch (isa) {
    case engine::cpu::Isa::Scalar: return dnnl_cpu_isa_sse41;  // oneDNN's floor: it has no scalar code
    case engine::cpu::Isa::Avx2: return dnnl_cpu_isa_avx2;
    case engine::cpu::Isa::Avx512: return dnnl_cpu_isa_avx512_core_bf16;
    case engine::cpu::Isa::Amx: return dnnl_cpu_isa_all;
  }
  return dnnl_cpu_isa_all;
}

// oneDNN fixes its ISA at its first JIT; this runs before any oneDNN call of
// ours, so TRANSGI_MAX_ISA caps its kernels as it caps the engine's.
void cap_onednn_isa() {
  static const bool done = [] {
    const engine::cpu::Isa isa = engine::cpu::effective_isa();
    if (isa == engine::cpu::Isa::Amx) return true;
    if (dnnl_set_max_cpu_isa(onednn_isa(isa)) != dnnl_success && isa < engine::cpu::detected_isa())
      throw std::runtime_error(std::string("oneDNN refused the ISA cap ") + engine::cpu::isa_name(isa) + " (" +
                               engine::cpu::max_isa_variable() + "): it had already chosen its kernels");
    return true;
  }();
  (void)done;
}

void reference_gemm(bool ta, bool tb, std::int64_t m, std::int64_t n, std::int64_t k, float alpha, const float* a,
                    std::int64_t lda, const float* b, std::int64_t ldb, float beta, float* c, std::int64_t ldc) {
  for (std::int64_t i = 0; i < m; ++i)
    for (std::int64_t j = 0; j < n; ++j) {
      double s = 0;  // double accumulation: the oracle should not be the noisy one
      for (std::int64_t p = 0; p < k; ++p) {
        const float av = ta ? a[p * lda + i] : a[i * lda + p];
        const float bv = tb ? b[j * ldb + p] : b[p * ldb + j];
        s += static_cast<double>(av) * bv;
      }
      float& out = c[i * ldc + j];
      out = static_cast<float>(alpha * s + (beta == 0.0f ? 0.0 : static_cast<double>(beta) * out));
    }
}
// ---- bfloat16 through the matmul primitive ---------------------------------

std::uint16_t to_bf16(float f) {
  std::uint32_t bits;
  std::memcpy(&bits, &f, 4);
  if ((bits & 0x7fffffffu) > 0x7f800000u) return static_cast<std::uint16_t>((bits >> 16) | 0x40);  // keep NaN a NaN
  bits += 0x7fffu + ((bits >> 16) & 1u);  // round to nearest even
  return static_cast<std::uint16_t>(bits >> 16);
}

// Copies the stored rows x cols region (leading dimension ld) to a packed bf16 buffer.
void pack_bf16(const float* src, std::int64_t rows, std::int64_t cols, std::int64_t ld, std::vector<std::uint16_t>& out) {
  out.resize(static_cast<std::size_t>(rows * cols));
  for (std::int64_t r = 0; r < rows; ++r)
    for (std::int64_t c = 0; c < cols; ++c) out[static_cast<std::size_t>(r * cols + c)] = to_bf16(src[r * ld + c]);
}

void check(dnnl_status_t st, const char* what) {
  if (st != dnnl_success) throw std::runtime_error(std::string("oneDNN ") + what + " failed with status " + std::to_string(static_cast<int>(st)));
}

class Bf16Matmul {
 public:
  static Bf16Matmul& instance() {
    static Bf16Matmul m;
    return m;
  }
  void run(bool ta, bool tb, std::int64_t m, std::int64_t n, std::int64_t k, float alpha, const float* a, std::int64_t lda,
           const float* b, std::int64_t ldb, float beta, float* c, std::int64_t ldc) {
    std::scoped_lock lock(mutex_);
    // Packed operands keep their stored orientation; strides express op().
    pack_bf16(a, ta ? k : m, ta ? m : k, lda, a16_);
    pack_bf16(b, tb ? n : k, tb ? k : n, ldb, b16_);
    tmp_.resize(static_cast<std::size_t>(m * n));
    const Key key{m, n, k, ta, tb};
    auto it = cache_.find(key);
    if (it == cache_.end()) it = cache_.emplace(key, create(key)).first;
    Entry& e = it->second;
    check(dnnl_memory_set_data_handle(e.a, a16_.data()), "set_data_handle");
    check(dnnl_memory_set_data_handle(e.b, b16_.data()), "set_data_handle");
    check(dnnl_memory_set_data_handle(e.c, tmp_.data()), "set_data_handle");
    dnnl_exec_arg_t args[3] = {{DNNL_ARG_SRC, e.a}, {DNNL_ARG_WEIGHTS, e.b}, {DNNL_ARG_DST, e.c}};
    check(dnnl_primitive_execute(e.primitive, stream_, 3, args), "matmul");
    check(dnnl_stream_wait(stream_), "stream wait");
    for (std::int64_t i = 0; i < m; ++i)
      for (std::int64_t j = 0; j < n; ++j) {
        float& out = c[i * ldc + j];
        const float v = alpha * tmp_[static_cast<std::size_t>(i * n + j)];
        out = beta == 0.0f ? v : v + beta * out;
      }
  }

 private:
  struct Key {
    std::int64_t m, n, k;
    bool ta, tb;
    auto operator<=>(const Key&) const = default;
  };
  struct Entry {
    dnnl_primitive_t primitive = nullptr;
    dnnl_memory_t a = nullptr, b = nullptr, c = nullptr;
  };
  Bf16Matmul() {
    cap_onednn_isa();
    check(dnnl_engine_create(&engine_, dnnl_cpu, 0), "engine_create");
    check(dnnl_stream_create(&stream_, engine_, dnnl_stream_default_flags), "stream_create");
  }
  ~Bf16Matmul() {
    for (auto& [key, e] : cache_) {
      dnnl_memory_destroy(e.a);
      dnnl_memory_destroy(e.b);
      dnnl_memory_destroy(e.c);
      dnnl_primitive_destroy(e.primitive);
    }
    if (stream_) dnnl_stream_destroy(stream_);
    if (engine_) dnnl_engine_destroy(engine_);
  }
  Bf16Matmul(const Bf16Matmul&) = delete;
  Bf16Matmul& operator=(const Bf16Matmul&) = delete;
  Entry create(const Key& key) {
    const dnnl_dims_t a_dims = {key.m, key.k}, b_dims = {key.k, key.n}, c_dims = {key.m, key.n};
    const dnnl_dims_t a_strides = {key.ta ? 1 : key.k, key.ta ? key.m : 1};
    const dnnl_dims_t b_strides = {key.tb ? 1 : key.n, key.tb ? key.k : 1};
    const dnnl_dims_t c_strides = {key.n, 1};
    dnnl_memory_desc_t a_md, b_md, c_md;
    check(dnnl_memory_desc_init_by_strides(&a_md, 2, a_dims, dnnl_bf16, a_strides), "memory_desc");
    check(dnnl_memory_desc_init_by_strides(&b_md, 2, b_dims, dnnl_bf16, b_strides), "memory_desc");
    check(dnnl_memory_desc_init_by_strides(&c_md, 2, c_dims, dnnl_f32, c_strides), "memory_desc");
    dnnl_matmul_desc_t desc;
    check(dnnl_matmul_desc_init(&desc, &a_md, &b_md, nullptr, &c_md), "matmul_desc_init");
    dnnl_primitive_desc_t pd;
    check(dnnl_primitive_desc_create(&pd, &desc, nullptr, engine_, nullptr), "primitive_desc_create");
    Entry e;
    check(dnnl_primitive_create(&e.primitive, pd), "primitive_create");
    dnnl_primitive_desc_destroy(pd);
    check(dnnl_memory_create(&e.a, &a_md, engine_, DNNL_MEMORY_NONE), "memory_create");
    check(dnnl_memory_create(&e.b, &b_md, engine_, DNNL_MEMORY_NONE), "memory_create");
    check(dnnl_memory_create(&e.c, &c_md, engine_, DNNL_MEMORY_NONE), "memory_create");
    return e;
  }

  std::mutex mutex_;
  dnnl_engine_t engine_ = nullptr;
  dnnl_stream_t stream_ = nullptr;
  std::map<Key, Entry> cache_;
  std::vector<std::uint16_t> a16_, b16_;
  std::vector<float> tmp_;
};

}  // namespace

void gemm(GemmBackend backend, bool ta, bool tb, std::int64_t m, std::int64_t n, std::int64_t k, float alpha,
          const float* a, std::int64_t lda, const float* b, std::int64_t ldb, float beta, float* c, std::int64_t ldc) {
  if (m == 0 || n == 0) return;
  if (backend == GemmBackend::Reference) {
    reference_gemm(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc);
    return;
  }
  if (backend == GemmBackend::OneDnnBf16) {
    if (!bf16_gemm_available())
      throw std::runtime_error(std::string("oneDNN has no bf16 matmul on ") + engine::cpu::isa_summary());
    Bf16Matmul::instance().run(ta, tb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc);
    return;
  }
  cap_onednn_isa();
  const dnnl_status_t st = dnnl_sgemm(ta ? 'T' : 'N', tb ? 'T' : 'N', m, n, k, alpha, a, lda, b, ldb, beta, c, ldc);
  if (st != dnnl_success) throw std::runtime_error("oneDNN sgemm failed with status " + std::to_string(static_cast<int>(st)));
}

bool bf16_gemm_available() {
  // Whether oneDNN has a bf16 matmul at the effective ISA is oneDNN's to say
  // (AVX-512 without BF16 emulates it; AVX2 has none in oneDNN 2.6), so ask it.
  static const bool available = [] {
    try {
      float a = 1, b = 1, c = 0;
      Bf16Matmul::instance().run(false, false, 1, 1, 1, 1.0f, &a, 1, &b, 1, 0.0f, &c, 1);
      return c == 1.0f;
    } catch (const std::runtime_error&) {
      return false;
    }
  }();
  return available;
}

std::string onednn_isa_name() {
  cap_onednn_isa();
  std::string name = dnnl_cpu_isa2str(dnnl_get_effective_cpu_isa());
  const std::string prefix = "cpu_isa_";
  return name.rfind(prefix, 0) == 0 ? name.substr(prefix.size()) : name;
}

GemmBackend default_gemm_backend() {
  if (const char* env = std::getenv("TRANSGI_GEMM")) {
    const std::string v = env;
    if (v == "reference") return GemmBackend::Reference;
    if (v == "f32") return GemmBackend::OneDnn;
    if (v == "bf16") return GemmBackend::OneDnnBf16;
  }
  return GemmBackend::OneDnn;
}

const char* gemm_backend_name(GemmBackend b) {
  switch (b) {
    case GemmBackend::Reference: return "reference";
    case GemmBackend::OneDnnBf16: return "oneDNN bf16";
    default: return "oneDNN f32";
  }
}

void set_gemm_threads(int threads) { omp_set_num_threads(threads > 0 ? threads : omp_get_num_procs()); }

GemmThreadsScope::GemmThreadsScope(int threads) : before_(omp_get_max_threads()) { omp_set_num_threads(threads); }
GemmThreadsScope::~GemmThreadsScope() { omp_set_num_threads(before_); }

}  // namespace transgi::model
