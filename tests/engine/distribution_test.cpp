#include <gtest/gtest.h>

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
