// shaders/probe_lights.comp against probes::interpolate_fields_with (its CPU
// stage): three cascades of probes updated in the sample level, each point
// looked up with a rotated copy of the SH or the world's, points inside the
// finest cascade, across the hand-over bands, in the coarsest alone and
// outside them all.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "engine/math/rng.h"
#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"
#include "eval/method_runs.h"
#include "gpu/vulkan_probe_kernels.h"
#include "gpu/vulkan_probe_lights.h"
#include "gpu_fixture.h"
#include "probe_kernels_fixture.h"
#include "probes/cascades.h"

using namespace transgi;
using namespace engine;

namespace {

struct Cascades {
  std::vector<std::unique_ptr<probes::ProbeField>> owned;
  std::vector<const probes::ProbeField*> fields;
};

// Three 6^3 cascades (0.4, 0.8, 1.6 m cells) centred on a point of the
// level, updated for 12 frames, the finer lit beyond their box by the
// coarser, as the plugin runs them, seen from that point.
Cascades level_cascades(const rt::RtScene& scene, const render::LightSet& lights, const glm::vec3& eye, int count = 3,
                        float finest_cell = 0.4f, bool far_field = false) {
  probes::CascadeSettings c;
  c.count = count;
  c.finest_cell = finest_cell;
  c.dims = glm::ivec3(6);
  Cascades out;
  for (int k = 0; k < c.count; ++k) {
    probes::ProbeFieldSettings s;
    s.grid = probes::cascade_grid(c, k, probes::cascade_origin(c, k, eye));
    s.map = probes::MapLayout{16, 8};
    s.rays_per_probe = 32;
    s.blend_cells = c.blend_cells;
    out.owned.push_back(std::make_unique<probes::ProbeField>(s));
  }
  if (far_field) {
    // A far field over the level's bounds, as follow_camera adds past the coarsest cascade.
    probes::ProbeFieldSettings s;
    s.grid = probes::ProbeGrid::centred_in(scene.bounds_min(), scene.bounds_max(), c.dims);
    s.map = probes::MapLayout{16, 8};
    s.rays_per_probe = 32;
    s.blend_cells = probes::kFallbackBlendCells;
    out.owned.push_back(std::make_unique<probes::ProbeField>(s));
  }
  // The camera at the eye, as the probe sync systems set it: both sides take the view bias.
  for (const auto& f : out.owned) f->set_viewer(eye);
  const int fields = static_cast<int>(out.owned.size());
  for (int frame = 0; frame < 12; ++frame)
    for (int k = fields - 1; k >= 0; --k)
      out.owned[static_cast<std::size_t>(k)]->update(scene, lights, k + 1 < fields ? out.owned[static_cast<std::size_t>(k) + 1].get() : nullptr);
  for (const auto& f : out.owned) out.fields.push_back(f.get());
  return out;
}

struct Compared {
  int points = 0, differ = 0, blended = 0, outside = 0, mean_light = 0;
};

// The device's lights at `n` random points (half near the eye, half in and
// around the coarsest cascade, a few far beyond) against
// interpolate_fields_with, with two rotated SH copies besides the world's.
Compared compare_lights(engine::gpu::VulkanContext& ctx, const Cascades& c, const glm::vec3& eye, int n, std::uint64_t seed) {
  // Two rotated copies besides the world's: random SH, the kernel only reads them.
  const int rotations = 2;
  math::Pcg32 rng(seed, 11);
  std::vector<std::vector<float>> copies;  // (r * fields + f) * 2 + direct
  for (int r = 0; r < rotations; ++r)
    for (const probes::ProbeField* f : c.fields)
      for (int d = 0; d < 2; ++d) {
        std::vector<float> v(f->light_sh_all().size());
        for (float& x : v) x = rng.next_float() - 0.25f;
        copies.push_back(std::move(v));
      }
  const auto index_of = [&](const probes::ProbeField* f) {
    return static_cast<std::size_t>(std::find(c.fields.begin(), c.fields.end(), f) - c.fields.begin());
  };
  const shading::ProbeLightMaker::ShOf sh = [&](int r, const probes::ProbeField* f, bool direct) -> const float* {
    if (r < 0) return (direct ? f->direct_sh_all() : f->light_sh_all()).data();
    return copies[(static_cast<std::size_t>(r) * c.fields.size() + index_of(f)) * 2 + (direct ? 1 : 0)].data();
  };

  std::vector<shading::ProbeLightMaker::Point> pts(static_cast<std::size_t>(n));
  // The coarsest cascade: the last field that is not a fallback (a far field).
  std::size_t last_cascade = c.fields.size() - 1;
  while (last_cascade > 0 && c.fields[last_cascade]->settings().blend_cells == probes::kFallbackBlendCells) --last_cascade;
  const probes::ProbeGrid& coarse = c.fields[last_cascade]->placement();
  for (auto& p : pts) {
    // Half in the finest cascade's neighbourhood, half anywhere in and just
    // outside the coarsest, a few far beyond it.
    const float u = rng.next_float();
    const bool near = u < 0.5f, far = u > 0.95f;
    glm::vec3 a = near ? eye - 1.6f : coarse.min - 0.5f, b = near ? eye + 1.6f : coarse.max + 0.5f;
    if (far) {
      a = coarse.max + 20.0f;
      b = coarse.max + 40.0f;
    }
    p.position = glm::mix(a, b, glm::vec3{rng.next_float(), rng.next_float(), rng.next_float()});
    p.normal = glm::normalize(glm::vec3{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f} + 1e-3f);
    p.rotation = static_cast<int>(rng.next_float() * (rotations + 1)) - 1;
  }

  transgi::gpu::VulkanProbeLights device(ctx);
  std::string why;
  EXPECT_TRUE(device.set_probes(c.fields, rotations, sh, &why)) << why;
  const auto mapped = device.points(n);
  std::copy(pts.begin(), pts.end(), mapped.begin());
  engine::gpu::GpuBuffer light(ctx, n * 75 * sizeof(float)), light2(ctx, n * 75 * sizeof(float));
  ctx.submit_and_wait([&](VkCommandBuffer cmd) { device.record(cmd, n, true, light, light2); });
  std::vector<float> got(static_cast<std::size_t>(n) * 75), got2(static_cast<std::size_t>(n) * 75);
  light.download(std::span<float>(got));
  light2.download(std::span<float>(got2));

  int differ = 0, blended = 0, outside = 0, mean_light = 0;
  float largest = 0;
  for (float v : got) largest = std::max(largest, std::abs(v));
  for (int i = 0; i < n; ++i) {
    const auto& p = pts[static_cast<std::size_t>(i)];
    float want[75], want2[75];
    probes::interpolate_fields_with(
        c.fields, p.position, p.normal, [&](const probes::ProbeField* f) { return sh(p.rotation, f, false); },
        [&](const probes::ProbeField* f) { return sh(p.rotation, f, true); }, want, want2);
    const probes::FieldMix m = probes::fields_at(c.fields, p.position);
    blended += m.count == 2;
    outside += !(glm::all(glm::greaterThanEqual(p.position, coarse.min)) && glm::all(glm::lessThanEqual(p.position, coarse.max)));
    bool same_as_mean = p.rotation < 0;
    for (int k = 0; k < 75 && same_as_mean; ++k) same_as_mean = want[k] == c.fields.back()->mean_light_sh()[k];
    mean_light += same_as_mean;
    float err = 0;
    for (int k = 0; k < 75; ++k) {
      err = std::max(err, std::abs(want[k] - got[static_cast<std::size_t>(i) * 75 + k]));
      err = std::max(err, std::abs(want2[k] - got2[static_cast<std::size_t>(i) * 75 + k]));
    }
    if (err > 1e-4f * largest) {
      if (differ < 5) std::printf("point %d: largest difference %g (rotation %d, %d fields mixed)\n", i, err, p.rotation, m.count);
      ++differ;
    }
  }
  std::printf("probe lights: %d points, %d across a hand-over band, %d outside every cascade, %d took the mean light; %d differ\n",
              n, blended, outside, mean_light, differ);
  return {n, differ, blended, outside, mean_light};
}

}  // namespace

// Every point's 150 values (indirect and direct light) to 1e-4 of the
// largest coefficient. The interpolation is the CPU's arithmetic, but the
// device may fuse multiply-adds: a point within rounding of a texel border,
// a visibility threshold or a box face may choose otherwise, so at most
// 0.5 % of the points may differ (measured: see the printed line).
TEST(VulkanProbeLights, EqualTheCpuFieldInterpolationAcrossCascadesAndRotations) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  eval::LoadedScene loaded = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  const rt::RtScene& scene = loaded.app->world().resource<rt::RtScene>();
  const render::LightSet lights(scene, render::gather_punctual_lights(loaded.app->world()), nullptr);
  const glm::vec3 lo = scene.bounds_min(), hi = scene.bounds_max(), eye = 0.5f * (lo + hi) + glm::vec3(0.7f, 0.1f, -0.4f);
  Cascades c;
  loaded.app->jobs().run([&] { c = level_cascades(scene, lights, eye); });

  const Compared got = compare_lights(*ctx, c, eye, 4000, 5);
  EXPECT_GT(got.blended, got.points / 50) << "some points should lie in the hand-over bands";
  EXPECT_GT(got.outside, got.points / 50) << "some points should lie outside every cascade";
  EXPECT_LE(got.differ, got.points / 200) << "expected at most 0.5 % of points to differ, got " << got.differ;
}

// Two small cascades (0.4 and 0.8 m cells, 4.8 m across) and a far field
// over the level: points past the cascades take the far field's light, and
// points in the coarsest cascade's band keep the cascades' (cascades.h's
// fallback box), on the device as on the CPU.
TEST(VulkanProbeLights, EqualTheCpuAcrossCascadesAndAFarField) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  eval::LoadedScene loaded = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  const rt::RtScene& scene = loaded.app->world().resource<rt::RtScene>();
  const render::LightSet lights(scene, render::gather_punctual_lights(loaded.app->world()), nullptr);
  const glm::vec3 eye = 0.5f * (scene.bounds_min() + scene.bounds_max()) + glm::vec3(0.7f, 0.1f, -0.4f);
  Cascades c;
  loaded.app->jobs().run([&] { c = level_cascades(scene, lights, eye, 2, 0.4f, true); });
  const Compared got = compare_lights(*ctx, c, eye, 4000, 13);
  EXPECT_GT(got.blended, got.points / 50) << "some points should lie in the hand-over band";
  EXPECT_GT(got.outside, got.points / 50) << "some points should lie past the cascades, in the far field";
  EXPECT_LE(got.differ, got.points / 200) << "expected at most 0.5 % of points to differ, got " << got.differ;
}

// Cascades over the level's roof and the empty sky above it: the probes up
// there see no surface within a cell (far), so points among them find no lit
// probe in any cascade and take the coarsest's mean light (world SH), or its
// black fallback blend (a rotated copy).
TEST(VulkanProbeLights, PointsWithNoLitProbeTakeTheCoarsestCascadesMeanLight) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  eval::LoadedScene loaded = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  const rt::RtScene& scene = loaded.app->world().resource<rt::RtScene>();
  const render::LightSet lights(scene, render::gather_punctual_lights(loaded.app->world()), nullptr);
  const glm::vec3 eye = 0.5f * (scene.bounds_min() + scene.bounds_max()) + glm::vec3(0.0f, 9.0f, 0.0f);
  Cascades c;
  loaded.app->jobs().run([&] { c = level_cascades(scene, lights, eye, 2, 2.0f); });
  ASSERT_GT(std::abs(c.fields.back()->mean_light_sh()[0]), 0.0f) << "a black mean would not tell the branch from a black blend";
  const Compared got = compare_lights(*ctx, c, eye, 2000, 9);
  EXPECT_GT(got.mean_light, got.points / 50) << "some points should find no lit probe and take the mean light";
  EXPECT_LE(got.differ, got.points / 200) << "expected at most 0.5 % of points to differ, got " << got.differ;
}

// A field on the Vulkan backend keeps its radiance maps on the device
// between updates (VulkanMapStore): its host copies stay as reset left
// them, and read_back_maps() brings the device's. A field switched to the
// CPU backend takes them along: its maps equal those of the same run read
// back, not the blank ones, and its next update continues from them.
TEST(VulkanMapStore, AFieldSwitchedToTheCpuTakesItsMapsFromTheDevice) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  OWN_PROBE_KERNELS_OR_SKIP(own);
  const std::shared_ptr<engine::gpu::VulkanContext>& ctx = own.ctx;
  const std::shared_ptr<transgi::gpu::VulkanProbeKernels>& kernels = own.kernels;
  eval::LoadedScene loaded = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  const rt::RtScene& scene = loaded.app->world().resource<rt::RtScene>();
  const render::LightSet lights(scene, render::gather_punctual_lights(loaded.app->world()), nullptr);
  probes::ProbeFieldSettings s;
  s.grid = probes::ProbeGrid::centred_in(scene.bounds_min(), scene.bounds_max(), glm::ivec3(4));
  s.map = probes::MapLayout{16, 8};
  s.rays_per_probe = 32;
  probes::ProbeField switched(s), stayed(s);
  loaded.app->jobs().run([&] {
    for (probes::ProbeField* f : {&switched, &stayed}) {
      f->set_kernels(kernels);
      for (int frame = 0; frame < 6; ++frame) f->update(scene, lights);
    }
  });
  std::size_t held = 0, blank = 0;
  for (const probes::ProbeMapState& m : stayed.states()) {
    if (m.device_stamp == 0) continue;
    ++held;
    bool any = false;
    for (const std::uint8_t v : m.sampled) any = any || v != 0;
    blank += any ? 0 : 1;
  }
  EXPECT_GT(held, stayed.states().size() / 2) << "most probes' maps should be held on the device";
  EXPECT_EQ(blank, held) << "the host's copies of maps the device holds are as reset left them";
  switched.set_kernels(nullptr);
  stayed.read_back_maps();
  std::size_t compared = 0, sampled = 0;
  for (std::size_t q = 0; q < stayed.states().size(); ++q) {
    const probes::ProbeMapState& a = switched.states()[q];
    const probes::ProbeMapState& b = stayed.states()[q];
    ASSERT_EQ(a.device_stamp, 0u);
    ASSERT_EQ(b.device_stamp, 0u);
    if (!b.held()) continue;
    ++compared;
    float largest = 0.0f, worst = 0.0f;
    for (std::size_t t = 0; t < b.sampled.size(); ++t) {
      sampled += b.sampled[t];
      largest = std::max(largest, b.radiance_at(t).g);
      worst = std::max(worst, std::abs(a.radiance_at(t).g - b.radiance_at(t).g));
    }
    EXPECT_LE(worst, 1e-2f * largest + 1e-6f) << "probe " << q;
  }
  EXPECT_GT(compared, 0u);
  EXPECT_GT(sampled, compared * 16 * 8 / 2) << "the maps read back should be mostly sampled";
  // The switched field's next update runs on the CPU from the maps it took.
  loaded.app->jobs().run([&] { switched.update(scene, lights); });
  EXPECT_EQ(ctx->validation_errors(), 0);
}
