#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "engine/math/distribution.h"
#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/scene/environment.h"

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

// The alias table holds exactly the bins' probabilities: bin i's mass is
// its own threshold plus what every bin aliased to it leaves, over n (a
// known answer from f), and its pdf is Distribution2D's on the same f.
TEST(AliasDistribution2D, EachBinHoldsItsProbabilityAndTheSamePdfAsTheSearchedTables) {
  for (const auto& [w, h] : {std::pair{8, 4}, std::pair{7, 5}, std::pair{64, 32}}) {
    const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
    std::vector<float> f(n);
    Pcg32 rng(static_cast<std::uint64_t>(w), 7);
    for (std::size_t i = 0; i < n; ++i) {
      // Mostly dark, a few bins a thousand times brighter (a sun), some zero.
      const float r = rng.next_float();
      f[i] = r < 0.2f ? 0.0f : r < 0.25f ? 1000.0f * rng.next_float() : rng.next_float();
    }
    const AliasDistribution2D alias(f, w, h);
    const Distribution2D searched(f, w, h);
    double sum = 0;
    for (const float v : f) sum += v;
    std::vector<double> mass(n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      const AliasDistribution2D::Entry& e = alias.entries()[i];
      ASSERT_GE(e.threshold, 0.0f);
      ASSERT_LE(e.threshold, 1.0f);
      ASSERT_LT(e.alias, n);
      mass[i] += e.threshold;
      mass[e.alias] += 1.0 - e.threshold;
    }
    for (std::size_t i = 0; i < n; ++i) {
      EXPECT_NEAR(mass[i] / static_cast<double>(n), f[i] / sum, 1e-6) << w << " x " << h << ", bin " << i;
      const glm::vec2 centre{(static_cast<float>(i % static_cast<std::size_t>(w)) + 0.5f) / static_cast<float>(w),
                             (static_cast<float>(i / static_cast<std::size_t>(w)) + 0.5f) / static_cast<float>(h)};
      EXPECT_NEAR(alias.pdf(centre), searched.pdf(centre), 1e-5f * searched.pdf(centre) + 1e-7f) << w << " x " << h << ", bin " << i;
    }
  }
}

// Samples land in each bin as often as its probability says (a histogram
// of 200,000 samples within 4 standard deviations), never in a zero bin,
// and each comes with the pdf of where it landed; an all-zero table is
// uniform.
TEST(AliasDistribution2D, SamplesFollowTheDensityTheyReport) {
  const int w = 16, h = 8;
  const std::size_t n = static_cast<std::size_t>(w * h);
  std::vector<float> f(n);
  for (std::size_t i = 0; i < n; ++i) f[i] = static_cast<float>((i * 7) % 5) * (i == 37 ? 50.0f : 1.0f);
  const AliasDistribution2D d(f, w, h);
  double sum = 0;
  for (const float v : f) sum += v;
  std::vector<int> count(n, 0);
  Pcg32 rng(11, 2);
  const int samples = 200000;
  for (int k = 0; k < samples; ++k) {
    float pdf = 0;
    const glm::vec2 uv = d.sample({rng.next_float(), rng.next_float()}, &pdf);
    ASSERT_GE(uv.x, 0.0f);
    ASSERT_LT(uv.x, 1.0f);
    ASSERT_GE(uv.y, 0.0f);
    ASSERT_LT(uv.y, 1.0f);
    const std::size_t bin = static_cast<std::size_t>(static_cast<int>(uv.y * h) * w + static_cast<int>(uv.x * w));
    ASSERT_GT(f[bin], 0.0f) << "a sample in a zero bin";
    ASSERT_EQ(pdf, d.pdf(uv));
    ++count[bin];
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double p = f[i] / sum, expected = p * samples;
    EXPECT_NEAR(count[i], expected, 4.0 * std::sqrt(expected * (1.0 - p)) + 1.0) << "bin " << i;
  }
  const AliasDistribution2D flat(std::vector<float>(n, 0.0f), w, h);
  float pdf = 0;
  const glm::vec2 uv = flat.sample({0.3f, 0.7f}, &pdf);
  EXPECT_EQ(pdf, 1.0f);
  EXPECT_EQ(flat.pdf(uv), 1.0f);
}

// An environment's importance sampling is unbiased: the mean of L / pdf over
// a million samples of a map with a small sun 2,000 times brighter than its
// sky equals the map's integral over the sphere (each texel's radiance times
// its solid angle), within 4 standard errors; each sample's pdf is the one
// Environment::pdf gives its direction (but for at most 1 in 10,000, within
// rounding of a texel's edge).
TEST(AliasDistribution2D, AnEnvironmentsSamplesIntegrateItsRadiance) {
  const int w = 64, h = 32;
  engine::image::ImageRGB img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at(x, y) = glm::vec3(0.2f + 0.6f * y / h, 0.5f, 1.0f - 0.5f * x / w);
  for (int y = 6; y < 8; ++y)
    for (int x = 20; x < 22; ++x) img.at(x, y) = glm::vec3(2000.0f, 1800.0f, 1500.0f);
  const engine::scene::Environment env(img, 1.0f, glm::mat4(1.0f));
  glm::dvec3 exact(0.0);
  for (int y = 0; y < h; ++y) {
    const double omega = (2.0 * 3.14159265358979 / w) * (std::cos(3.14159265358979 * y / h) - std::cos(3.14159265358979 * (y + 1) / h));
    for (int x = 0; x < w; ++x) exact += glm::dvec3(img.at(x, y)) * omega;
  }
  Pcg32 rng(17, 5);
  const int n = 1000000;
  glm::dvec3 sum(0.0), sum2(0.0);
  float worst = 0.0f;
  int other_texel = 0;
  for (int k = 0; k < n; ++k) {
    glm::vec3 dir;
    float pdf = 0;
    const glm::vec3 l = env.sample({rng.next_float(), rng.next_float()}, &dir, &pdf);
    ASSERT_GT(pdf, 0.0f);
    // The same texel's pdf: only the solid angle's sin(theta), once from v and
    // once from the direction's y, rounds otherwise (under 1 % but at the
    // poles), but for a sample within rounding of its texel's edge, which the
    // direction can put in the next texel.
    const float off = std::abs(pdf - env.pdf(dir)) / pdf;
    if (off > 1e-2f) ++other_texel;
    else worst = std::max(worst, off);
    const glm::dvec3 e = glm::dvec3(l) / static_cast<double>(pdf);
    sum += e;
    sum2 += e * e;
  }
  std::printf("largest relative difference of a sample's pdf and pdf(direction): %.3g; %d of %d in another texel\n", worst,
              other_texel, n);
  EXPECT_LE(other_texel, n / 10000);
  for (int c = 0; c < 3; ++c) {
    const double mean = sum[c] / n, sigma = std::sqrt(std::max(0.0, sum2[c] / n - mean * mean) / n);
    std::printf("channel %d: integral %.6g, mean of L / pdf %.6g +- %.2g\n", c, exact[c], mean, sigma);
    EXPECT_NEAR(mean, exact[c], 4.0 * sigma + 1e-6 * exact[c]) << "channel " << c;
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
