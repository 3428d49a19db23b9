#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/math/distribution.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"

using namespace engine::math;

TEST(Distribution1D, SamplesFollowTheFunction) {
  const std::vector<float> f = {1, 0, 3, 4};
  const Distribution1D d(f);
  EXPECT_NEAR(d.integral(), 2.0, 1e-9);  // (1+0+3+4)/4
  std::vector<int> counts(4, 0);
  Pcg32 rng(1, 2);
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    std::size_t idx = 0;
    float pdf = 0;
    const float x = d.sample_continuous(rng.next_float(), &pdf, &idx);
    ASSERT_GE(x, 0.0f);
    ASSERT_LT(x, 1.0f);
    ASSERT_EQ(idx, static_cast<std::size_t>(x * 4));
    EXPECT_FLOAT_EQ(pdf, d.pdf(x));
    ++counts[idx];
  }
  EXPECT_EQ(counts[1], 0) << "a zero bin must never be sampled";
  EXPECT_NEAR(counts[0] / double(n), 1.0 / 8, 0.005);
  EXPECT_NEAR(counts[2] / double(n), 3.0 / 8, 0.005);
  EXPECT_NEAR(counts[3] / double(n), 4.0 / 8, 0.005);
}

// The guide table only narrows the search: every u must land on the bin a
// binary search over the whole CDF finds (the largest i with cdf[i] <= u),
// with the same offset, for tables with runs of zero bins, one bin, sizes
// either side of a multiple of the guide's 8 bins, and u on and beside the
// guide's thresholds k / G and the CDF's own entries.
TEST(Distribution1D, TheGuidedSearchFindsTheBinOfAFullBinarySearch) {
  Pcg32 rng(3, 4);
  for (const std::size_t n : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{8}, std::size_t{9},
                              std::size_t{1000}, std::size_t{2048}}) {
    std::vector<float> f(n);
    for (std::size_t i = 0; i < n; ++i) f[i] = (i % 5 == 1 || (i > n / 3 && i < n / 2)) ? 0.0f : rng.next_float() * 10.0f;
    const Distribution1D d(f);
    const std::vector<double>& cdf = d.cdf();
    std::vector<float> us;
    for (int k = 0; k < 4000; ++k) us.push_back(rng.next_float());
    const std::size_t g = std::max<std::size_t>(1, (n + 7) / 8);
    for (std::size_t k = 0; k <= g; ++k) {
      const float t = static_cast<float>(static_cast<double>(k) / static_cast<double>(g));
      for (const float v : {t, std::nextafter(t, 0.0f), std::nextafter(t, 1.0f)}) us.push_back(v);
    }
    for (const double c : cdf) {
      const float v = static_cast<float>(c);
      for (const float w : {v, std::nextafter(v, 0.0f), std::nextafter(v, 1.0f)}) us.push_back(w);
    }
    for (float u : us) {
      u = std::clamp(u, 0.0f, 1.0f - 0x1p-24f);
      const auto it = std::upper_bound(cdf.begin(), cdf.end(), static_cast<double>(u));
      const std::size_t want = std::min(n - 1, static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - cdf.begin()) - 1)));
      std::size_t got = 0;
      float pdf = 0;
      const float x = d.sample_continuous(u, &pdf, &got);
      ASSERT_EQ(got, want) << "n " << n << ", u " << u;
      double du = static_cast<double>(u) - cdf[want];
      if (cdf[want + 1] > cdf[want]) du /= cdf[want + 1] - cdf[want];
      ASSERT_EQ(x, std::min(static_cast<float>((static_cast<double>(want) + du) / static_cast<double>(n)), 1.0f - 0x1p-24f));
    }
  }
}

TEST(Distribution2D, PdfIntegratesToOneAndMatchesSampling) {
  const int w = 8, h = 4;
  std::vector<float> f(w * h);
  for (int i = 0; i < w * h; ++i) f[static_cast<std::size_t>(i)] = static_cast<float>((i * 7) % 5);
  const Distribution2D d(f, w, h);
  double integral = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) integral += d.pdf({(x + 0.5f) / w, (y + 0.5f) / h}) / (w * h);
  EXPECT_NEAR(integral, 1.0, 1e-5);
  Pcg32 rng(3, 4);
  for (int i = 0; i < 1000; ++i) {
    float pdf = 0;
    const glm::vec2 uv = d.sample({rng.next_float(), rng.next_float()}, &pdf);
    EXPECT_NEAR(pdf, d.pdf(uv), 1e-4f * pdf);
    EXPECT_GT(f[static_cast<std::size_t>(int(uv.y * h) * w + int(uv.x * w))], 0.0f);
  }
}

TEST(Sampling, CosineHemisphereAndFrameRoundTrip) {
  Pcg32 rng(5, 6);
  for (int i = 0; i < 1000; ++i) {
    const glm::vec3 n = sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const Frame f = Frame::from_normal(n);
    EXPECT_NEAR(glm::dot(f.t, f.b), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::dot(f.t, f.n), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(f.t), 1.0f, 1e-5f);
    const glm::vec3 v = sample_cosine_hemisphere({rng.next_float(), rng.next_float()});
    EXPECT_NEAR(glm::length(v), 1.0f, 1e-5f);
    const glm::vec3 back = f.to_local(f.to_world(v));
    EXPECT_NEAR(glm::length(back - v), 0.0f, 1e-5f);
  }
}

TEST(Sampling, TriangleSamplesAreUniform) {
  // Mean of uniform barycentrics is (1/3, 1/3).
  Pcg32 rng(9, 9);
  double s1 = 0, s2 = 0;
  const int n = 100000;
  for (int i = 0; i < n; ++i) {
    const glm::vec2 b = sample_uniform_triangle({rng.next_float(), rng.next_float()});
    ASSERT_GE(b.x, 0.0f);
    ASSERT_GE(b.y, 0.0f);
    ASSERT_LE(b.x + b.y, 1.0f + 1e-6f);
    s1 += b.x;
    s2 += b.y;
  }
  EXPECT_NEAR(s1 / n, 1.0 / 3, 0.003);
  EXPECT_NEAR(s2 / n, 1.0 / 3, 0.003);
}

TEST(Rng, StreamsAreReproducibleAndDistinct) {
  Pcg32 a = make_rng(1, 100, 0), b = make_rng(1, 100, 0), c = make_rng(1, 101, 0);
  const std::uint32_t x = a.next_u32();
  EXPECT_EQ(x, b.next_u32());
  EXPECT_NE(x, c.next_u32());
}
