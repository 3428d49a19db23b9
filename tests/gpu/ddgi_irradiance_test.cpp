// shaders/ddgi_irradiance.comp against ddgi::DdgiVolume::irradiance (its CPU
// stage): a floor with a box on it under a uniform sky (floor_under_sky.h), probes on a scrolled
// grid after 40 updates, 4,000 random shading points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "engine/math/rng.h"
#include "gpu/vulkan_ddgi_irradiance.h"
#include "../transgi/floor_under_sky.h"
#include "gpu_fixture.h"

using namespace engine;


// The kernel is the CPU's arithmetic in its order, but pow, normalize and
// fused multiply-adds round differently on the device: 1e-4 of the point's
// irradiance plus 1e-5 absolute (measured: see output).
TEST(VulkanDdgiIrradiance, EqualsTheCpuStageOnAScrolledGrid) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const scene::MeshAsset box = scene::make_box(glm::vec3(0.4f, 0.6f, 0.3f));
  FloorUnderSky s(0.5f, &box, glm::vec3(0.3f, 0.6f, -0.2f));
  transgi::ddgi::DdgiSettings settings;
  settings.escaped = transgi::ddgi::EscapedRays::Environment;
  settings.rays_per_probe = 64;
  settings.warmup_frames = 8;
  transgi::probes::ProbeGrid grid{glm::vec3(-1.5f, 0.2f, -1.5f), glm::vec3(1.5f, 1.8f, 1.5f), glm::ivec3(4, 3, 4)};
  grid.scroll = glm::ivec3(1, 0, 2);
  transgi::ddgi::DdgiVolume volume(grid, settings);
  const render::LightSet no_lights;
  const auto& assets = s.app.world().resource<scene::SceneAssets>();
  s.app.jobs().run([&] {
    for (int f = 0; f < 40; ++f) volume.update(s.app.world().resource<rt::RtScene>(), no_lights, &*assets.environment);
  });
  math::Pcg32 rng(8, 2);
  auto unit = [&] {
    return glm::normalize(glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f) + glm::vec3(1e-3f));
  };
  const int n = 4000;
  std::vector<glm::vec3> pos(n), nrm(n), view(n);
  for (int i = 0; i < n; ++i) {
    pos[static_cast<std::size_t>(i)] = glm::vec3(4.0f * rng.next_float() - 2.0f, 2.2f * rng.next_float(), 4.0f * rng.next_float() - 2.0f);
    nrm[static_cast<std::size_t>(i)] = unit();
    view[static_cast<std::size_t>(i)] = unit();
  }
  transgi::gpu::VulkanDdgiIrradiance kernel(*ctx);
  const auto got = kernel.irradiance(volume, pos, nrm, view);
  int bad = 0, lit = 0;
  float worst = 0;
  double mean = 0;
  for (int i = 0; i < n; ++i) {
    bool want_lit = false;
    const glm::vec3 want = volume.irradiance(pos[static_cast<std::size_t>(i)], nrm[static_cast<std::size_t>(i)], view[static_cast<std::size_t>(i)], &want_lit);
    const glm::vec3 g = got.irradiance[static_cast<std::size_t>(i)];
    lit += want_lit;
    mean += want.g;
    EXPECT_EQ(got.lit[static_cast<std::size_t>(i)] != 0, want_lit) << "point " << i;
    for (int c = 0; c < 3; ++c) {
      const float err = std::abs(g[c] - want[c]);
      worst = std::max(worst, err / std::max(1e-3f, want[c]));
      if (!(err <= 1e-4f * std::abs(want[c]) + 1e-5f) && bad++ < 5)
        ADD_FAILURE() << "point " << i << " channel " << c << ": expected " << want[c] << ", got " << g[c];
    }
  }
  std::printf("ddgi: %d points, %d lit, mean irradiance %.3f, worst relative difference %.2g\n", n, lit, mean / n, worst);
  EXPECT_EQ(bad, 0);
  EXPECT_GT(lit, n / 2);
  EXPECT_EQ(ctx->validation_errors(), 0);
}
