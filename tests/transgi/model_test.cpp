// The decoder and latents: the oneDNN GEMM against the reference loop, a
// finite-difference gradient check of the MLP (parameters and inputs) and of
// the latent interpolation, and welding across seams.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "engine/core/cpu_isa.h"
#include "engine/math/rng.h"
#include "engine/scene/procedural.h"
#include "model/gemm.h"
#include "model/latent_mesh.h"
#include "model/mlp.h"

using namespace transgi::model;

namespace {
std::vector<float> random_vector(std::size_t n, std::uint64_t seed, float scale = 1.0f) {
  engine::math::Pcg32 rng(seed, 9);
  std::vector<float> v(n);
  for (float& x : v) x = scale * (2.0f * rng.next_float() - 1.0f);
  return v;
}
}  // namespace

TEST(Gemm, OneDnnMatchesTheReferenceForEveryTransposeCombination) {
  const int m = 37, n = 29, k = 53;
  for (bool ta : {false, true})
    for (bool tb : {false, true}) {
      const auto a = random_vector(static_cast<std::size_t>(m) * k, 1), b = random_vector(static_cast<std::size_t>(k) * n, 2);
      auto c_ref = random_vector(static_cast<std::size_t>(m) * n, 3), c_fast = c_ref;
      const int lda = ta ? m : k, ldb = tb ? k : n;
      gemm(GemmBackend::Reference, ta, tb, m, n, k, 0.7f, a.data(), lda, b.data(), ldb, 0.5f, c_ref.data(), n);
      gemm(GemmBackend::OneDnn, ta, tb, m, n, k, 0.7f, a.data(), lda, b.data(), ldb, 0.5f, c_fast.data(), n);
      for (std::size_t i = 0; i < c_ref.size(); ++i)
        ASSERT_NEAR(c_fast[i], c_ref[i], 1e-4f) << "ta " << ta << " tb " << tb << " element " << i;
    }
}

TEST(Gemm, OneDnnRunsAtTheEffectiveIsa) {
  // TRANSGI_MAX_ISA reaches oneDNN: capped at avx2 it must not use AVX-512.
  const std::string isa = onednn_isa_name();
  std::printf("oneDNN: %s on %s\n", isa.c_str(), engine::cpu::isa_summary().c_str());
  switch (engine::cpu::effective_isa()) {
    case engine::cpu::Isa::Scalar: EXPECT_EQ(isa, "sse41"); break;
    case engine::cpu::Isa::Avx2: EXPECT_EQ(isa, "avx2"); break;
    case engine::cpu::Isa::Avx512: EXPECT_NE(isa.find("avx512"), std::string::npos) << isa; break;
    case engine::cpu::Isa::Amx: EXPECT_NE(isa.find("amx"), std::string::npos) << isa; break;
  }
}

TEST(Gemm, Bf16MatchesTheReferenceWithinBf16Rounding) {
  // Each operand is rounded to 8 significant bits (relative error <= 2^-8),
  // so |C_bf16 - C| <= ~2 * 2^-8 * sum_p |a_ip| |b_pj| (+ f32 accumulation).
  if (!bf16_gemm_available()) GTEST_SKIP() << "oneDNN has no bf16 matmul on " << engine::cpu::isa_summary();
  const int m = 37, n = 29, k = 53;
  for (bool ta : {false, true})
    for (bool tb : {false, true}) {
      const auto a = random_vector(static_cast<std::size_t>(m) * k, 1), b = random_vector(static_cast<std::size_t>(k) * n, 2);
      auto c_ref = random_vector(static_cast<std::size_t>(m) * n, 3), c_bf = c_ref;
      const auto c0 = c_ref;
      const int lda = ta ? m : k, ldb = tb ? k : n;
      gemm(GemmBackend::Reference, ta, tb, m, n, k, 0.7f, a.data(), lda, b.data(), ldb, 0.5f, c_ref.data(), n);
      gemm(GemmBackend::OneDnnBf16, ta, tb, m, n, k, 0.7f, a.data(), lda, b.data(), ldb, 0.5f, c_bf.data(), n);
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < n; ++j) {
          double bound = 0;
          for (int p = 0; p < k; ++p)
            bound += std::abs((ta ? a[p * lda + i] : a[i * lda + p]) * (tb ? b[j * ldb + p] : b[p * ldb + j]));
          bound = 0.7 * 2.0 * std::ldexp(bound, -8) + 1e-5;
          const std::size_t e = static_cast<std::size_t>(i * n + j);
          ASSERT_NEAR(c_bf[e], c_ref[e], bound) << "ta " << ta << " tb " << tb << " element " << e;
        }
    }
}

namespace {
// The default decoder's outputs for 64 random inputs, through `backend`.
std::vector<float> default_mlp_outputs(GemmBackend backend) {
  Mlp net(MlpLayout{});
  net.initialise(5);
  const int batch = 64;
  const auto x = random_vector(static_cast<std::size_t>(batch) * 16, 6);
  std::vector<float> y(static_cast<std::size_t>(batch) * 75);
  MlpWorkspace ws;
  net.forward(x.data(), batch, y.data(), ws, backend);
  return y;
}
}  // namespace

TEST(Mlp, ForwardMatchesBetweenBackends) {
  const auto y_ref = default_mlp_outputs(GemmBackend::Reference), y_fast = default_mlp_outputs(GemmBackend::OneDnn);
  for (std::size_t i = 0; i < y_ref.size(); ++i) ASSERT_NEAR(y_fast[i], y_ref[i], 1e-4f) << i;
  EXPECT_EQ(MlpLayout{}.parameter_count(), 16u * 128 + 128 + 2 * (128 * 128 + 128) + 128 * 75 + 75);
  EXPECT_DOUBLE_EQ(MlpLayout{}.flops_per_sample(), 88832.0) << "the figure quoted in the developers' guide";
}

TEST(Mlp, Bf16ForwardAgreesToTwoSignificantDigits) {
  if (!bf16_gemm_available()) GTEST_SKIP() << "oneDNN has no bf16 matmul on " << engine::cpu::isa_summary();
  const auto y_ref = default_mlp_outputs(GemmBackend::Reference), y_bf = default_mlp_outputs(GemmBackend::OneDnnBf16);
  double err = 0, norm = 0;
  for (std::size_t i = 0; i < y_ref.size(); ++i) {
    err += (y_bf[i] - y_ref[i]) * (y_bf[i] - y_ref[i]);
    norm += y_ref[i] * y_ref[i];
  }
  EXPECT_LT(std::sqrt(err / norm), 0.02) << "relative RMS difference of bf16 vs f32 outputs";
}

TEST(Mlp, GradientMatchesFiniteDifferences) {
  // L = sum_i w_i y_i with fixed random w, so dL/dy = w. Central differences
  // in double-checked float: step 1e-2 on a small net keeps ReLU kinks rare;
  // a point whose perturbation crosses a kink would show as a large error.
  const MlpLayout layout{.inputs = 5, .width = 8, .hidden_layers = 2, .outputs = 4};
  Mlp net(layout);
  net.initialise(11);
  for (float& p : net.params()) p += 0.05f;  // non-zero biases exercise their gradients
  const int batch = 3;
  const auto x = random_vector(static_cast<std::size_t>(batch) * layout.inputs, 12);
  const auto w = random_vector(static_cast<std::size_t>(batch) * layout.outputs, 13);
  auto loss = [&](const Mlp& m, const std::vector<float>& in) {
    std::vector<float> y(w.size());
    MlpWorkspace ws;
    m.forward(in.data(), batch, y.data(), ws, GemmBackend::Reference);
    double s = 0;
    for (std::size_t i = 0; i < y.size(); ++i) s += static_cast<double>(w[i]) * y[i];
    return s;
  };
  std::vector<float> y(w.size()), grad(layout.parameter_count(), 0.0f), dx(x.size());
  MlpWorkspace ws;
  net.forward(x.data(), batch, y.data(), ws, GemmBackend::Reference);
  net.backward(x.data(), batch, w.data(), ws, grad, dx.data(), GemmBackend::Reference);

  const float h = 1e-2f;
  int checked = 0;
  for (std::size_t i = 0; i < net.params().size(); ++i) {
    Mlp plus = net, minus = net;
    plus.params()[i] += h;
    minus.params()[i] -= h;
    const double fd = (loss(plus, x) - loss(minus, x)) / (2.0 * h);
    EXPECT_NEAR(grad[i], fd, 2e-3 * (1.0 + std::abs(fd))) << "parameter " << i << ": expected " << fd << " got " << grad[i];
    ++checked;
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    auto xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const double fd = (loss(net, xp) - loss(net, xm)) / (2.0 * h);
    EXPECT_NEAR(dx[i], fd, 2e-3 * (1.0 + std::abs(fd))) << "input " << i;
  }
  EXPECT_EQ(checked, static_cast<int>(layout.parameter_count()));

  // The fast backend computes the same gradient.
  std::vector<float> grad_fast(grad.size(), 0.0f), dx_fast(dx.size());
  net.forward(x.data(), batch, y.data(), ws, GemmBackend::OneDnn);
  net.backward(x.data(), batch, w.data(), ws, grad_fast, dx_fast.data(), GemmBackend::OneDnn);
  for (std::size_t i = 0; i < grad.size(); ++i) ASSERT_NEAR(grad_fast[i], grad[i], 1e-4f) << i;
}

TEST(Latents, InterpolationGradientMatchesFiniteDifferences) {
  const auto mesh = engine::scene::make_uv_sphere(1.0f, 8, 4);
  LatentTable t = make_latent_table(mesh, 3);
  t.values = random_vector(t.values.size(), 21);
  const std::uint32_t tri = 5;
  const glm::vec2 bary(0.2f, 0.3f);
  const auto dz = random_vector(3, 22);  // L = dz . z
  std::vector<float> grad(t.values.size(), 0.0f);
  t.scatter_gradient(mesh, tri, bary, dz.data(), grad);
  const float h = 1e-2f;
  for (std::size_t i = 0; i < t.values.size(); ++i) {
    LatentTable p = t, m = t;
    p.values[i] += h;
    m.values[i] -= h;
    float zp[3], zm[3];
    p.interpolate(mesh, tri, bary, zp);
    m.interpolate(mesh, tri, bary, zm);
    double fd = 0;
    for (int d = 0; d < 3; ++d) fd += dz[d] * (zp[d] - zm[d]) / (2.0 * h);
    EXPECT_NEAR(grad[i], fd, 1e-4) << "latent value " << i;
  }
}

TEST(Latents, SeamVerticesAtOnePositionShareOneLatent) {
  // The UV sphere duplicates the seam column (u = 0 and u = 1) and the pole rows.
  const auto mesh = engine::scene::make_uv_sphere(1.0f, 8, 4);
  const LatentTable t = make_latent_table(mesh, 7);
  EXPECT_EQ(mesh.positions.size(), 9u * 5u);
  EXPECT_EQ(t.rows(), 8u * 3u + 2u) << "3 rings of 8 plus the two poles";
  EXPECT_EQ(t.vertex_to_latent[0], t.vertex_to_latent[8]) << "pole vertices weld";
  EXPECT_EQ(t.vertex_to_latent[9], t.vertex_to_latent[17]) << "u = 0 and u = 1 weld";
}

// The bake's sparse latent gradient (each gradient block sums only the rows
// its samples touch, Trainer::compute_block) against the dense scatter: the
// same additions in the same order, so the same bits, for samples that share
// rows (neighbouring triangles, the sphere's welded seam and poles).
TEST(Latents, SparseRowScatterEqualsTheDenseScatterBitForBit) {
  const auto mesh = engine::scene::make_uv_sphere(1.0f, 8, 4);
  const LatentTable t = make_latent_table(mesh, 7);
  engine::math::Pcg32 rng(5, 6);
  std::vector<float> dense(t.values.size(), 0.0f);
  struct Sample {
    std::uint32_t tri;
    glm::vec2 bary;
    std::vector<float> dz;
  };
  std::vector<Sample> samples;
  std::vector<std::uint64_t> rows;
  constexpr std::uint64_t kFirstRow = 1000;  // the table's rows after another mesh's
  for (int i = 0; i < 200; ++i) {
    Sample s{static_cast<std::uint32_t>(rng.next_u32() % mesh.triangles.size()), {0.0f, 0.0f}, random_vector(7, 100 + i)};
    s.bary.x = rng.next_float();
    s.bary.y = (1.0f - s.bary.x) * rng.next_float();
    t.scatter_gradient(mesh, s.tri, s.bary, s.dz.data(), dense);
    const glm::uvec3 tri = mesh.triangles[s.tri];
    for (std::uint32_t v : {tri.x, tri.y, tri.z}) rows.push_back(kFirstRow + t.vertex_to_latent[v]);
    samples.push_back(std::move(s));
  }
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  std::vector<float> sparse(rows.size() * 7, 0.0f);
  for (const Sample& s : samples) t.scatter_gradient_rows(mesh, s.tri, s.bary, s.dz.data(), kFirstRow, rows, sparse);
  ASSERT_LT(rows.size(), t.rows() + 1);
  std::vector<float> expected;
  for (const std::uint64_t r : rows) {
    const float* g = dense.data() + (r - kFirstRow) * 7;
    expected.insert(expected.end(), g, g + 7);
  }
  EXPECT_EQ(sparse, expected);
  // Every row with a value is listed.
  std::size_t nonzero_rows = 0;
  for (std::size_t r = 0; r < t.rows(); ++r)
    nonzero_rows += std::any_of(dense.begin() + r * 7, dense.begin() + r * 7 + 7, [](float v) { return v != 0.0f; }) ? 1 : 0;
  EXPECT_EQ(nonzero_rows, rows.size());
}
