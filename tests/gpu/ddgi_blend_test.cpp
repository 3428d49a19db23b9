// shaders/ddgi_blend.comp against ddgi::blend_irradiance and blend_distance
// (its CPU stage): 24 probes of random ray records (misses, back faces, a
// few probes past the back-face limit, a few with no records this frame)
// into random prior maps (some probes' light nearly out, so their texels
// darken past the threshold), with and without the brightness clamp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/math/rng.h"
#include "gpu/vulkan_ddgi_blend.h"
#include "gpu_fixture.h"

using namespace transgi;

namespace {

struct Maps {
  std::vector<ddgi::OctahedralMap<glm::vec3>> irradiance;
  std::vector<ddgi::OctahedralMap<glm::vec2>> distance;
};

}  // namespace

// The kernel is the CPU's arithmetic texel by texel, summed in the same ray
// order; pow and normalize round differently on the device: 1e-4 relative
// plus 1e-6 (measured: see output).
TEST(VulkanDdgiBlend, EqualsTheCpuBlendWithAndWithoutTheBrightnessClamp) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  ddgi::DdgiSettings s;
  s.rays_per_probe = 64;
  const int probes = 24;
  engine::math::Pcg32 rng(31, 4);
  auto unit = [&] {
    return glm::normalize(glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) + glm::vec3(1e-3f));
  };
  Maps prior;
  std::vector<std::vector<ddgi::RayRecord>> records(probes);
  for (int q = 0; q < probes; ++q) {
    prior.irradiance.emplace_back(s.irradiance_texels, glm::vec3(0.0f));
    prior.distance.emplace_back(s.distance_texels, glm::vec2(0.0f));
    for (auto& t : prior.irradiance.back().texels) t = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
    for (auto& t : prior.distance.back().texels) {
      const float d = 0.5f + 2.5f * rng.next_float();
      t = glm::vec2(d, d * d * (1.0f + 0.1f * rng.next_float()));
    }
    if (q % 8 == 5) continue;  // no records this frame: left as it is
    const float backface_rate = q % 8 == 3 ? 0.3f : 0.03f;  // q = 3, 11, 19: past the limit
    // q = 6, 14, 22: the light went nearly out, so texels darken by more than
    // the irradiance threshold and blend faster.
    const float brightness = q % 8 == 6 ? 1e-3f : 1.0f;
    for (int i = 0; i < s.rays_per_probe; ++i) {
      ddgi::RayRecord r{unit(), brightness * glm::vec3(2.0f * rng.next_float(), 2.0f * rng.next_float(), 2.0f * rng.next_float()), 0.0f};
      const float u = rng.next_float();
      r.distance = u < 0.1f ? 1e27f : u < 0.1f + backface_rate ? -0.2f * (0.1f + 3.0f * rng.next_float()) : 0.1f + 3.0f * rng.next_float();
      records[static_cast<std::size_t>(q)].push_back(r);
    }
  }
  gpu::VulkanDdgiBlend kernel(*ctx);
  for (const bool clamp : {true, false}) {
    Maps want = prior, got = prior;
    const float h = 0.9f, max_distance = 2.5f;
    for (int q = 0; q < probes; ++q) {
      const auto& rec = records[static_cast<std::size_t>(q)];
      if (rec.empty()) continue;
      ddgi::blend_irradiance(want.irradiance[static_cast<std::size_t>(q)], rec, s, h, clamp);
      ddgi::blend_distance(want.distance[static_cast<std::size_t>(q)], rec, s, max_distance, h);
    }
    kernel.blend(got.irradiance, got.distance, records, s, h, clamp, max_distance);
    int bad = 0, changed = 0;
    float worst = 0;
    auto check = [&](float w, float g, const char* what, int q, std::size_t t) {
      worst = std::max(worst, std::abs(w - g) / std::max(1e-3f, std::abs(w)));
      if (!(std::abs(w - g) <= 1e-4f * std::abs(w) + 1e-6f) && bad++ < 5)
        ADD_FAILURE() << (clamp ? "clamped: " : "unclamped: ") << what << " probe " << q << " texel " << t << ": expected " << w << ", got " << g;
    };
    for (int q = 0; q < probes; ++q)
      for (std::size_t t = 0; t < want.irradiance[static_cast<std::size_t>(q)].texels.size(); ++t) {
        const glm::vec3 w = want.irradiance[static_cast<std::size_t>(q)].texels[t], g = got.irradiance[static_cast<std::size_t>(q)].texels[t];
        changed += w != prior.irradiance[static_cast<std::size_t>(q)].texels[t];
        for (int c = 0; c < 3; ++c) check(w[c], g[c], "irradiance", q, t);
      }
    for (int q = 0; q < probes; ++q)
      for (std::size_t t = 0; t < want.distance[static_cast<std::size_t>(q)].texels.size(); ++t)
        for (int c = 0; c < 2; ++c)
          check(want.distance[static_cast<std::size_t>(q)].texels[t][c], got.distance[static_cast<std::size_t>(q)].texels[t][c], "distance", q, static_cast<int>(t));
    std::printf("ddgi blend (%s): %d irradiance texels changed, worst relative difference %.2g\n", clamp ? "clamped" : "unclamped",
                changed, worst);
    EXPECT_EQ(bad, 0);
    EXPECT_GT(changed, 100) << "the blend should move most texels";
    // Probes past the back-face limit keep their irradiance on both sides.
    EXPECT_EQ(got.irradiance[3].texels, prior.irradiance[3].texels);
  }
  EXPECT_EQ(ctx->validation_errors(), 0);
}
