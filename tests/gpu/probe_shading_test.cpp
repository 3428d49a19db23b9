// The probe rays' chain on the device (probe_rays.comp, rt_query.comp,
// probe_hit_begin.comp, rt_query.comp for the shadow rays,
// probe_hit_finish.comp) against probes::begin_probe_ray / finish_probe_ray
// (the CPU stages) on the same hits and random numbers: the sample level (textures, its sun) with every
// kind of light added (a point and a spot light, a sun with a disk, a
// non-uniform environment map importance-sampled, emissive triangles), the
// bounce light from a random probe field inside a box and an outer one
// beyond it.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/gpu/gpu_error.h"
#include "engine/gpu/gpu_ray_tracer.h"
#include "engine/math/rng.h"
#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/environment.h"
#include "engine/scene/scene_assets.h"
#include "eval/method_runs.h"
#include "gpu/vulkan_probe_kernels.h"
#include "gpu/vulkan_probe_shading.h"
#include "gpu_fixture.h"
#include "probe_kernels_fixture.h"
#include "probes/cpu_probe_kernels.h"
#include "probes/probe_map.h"
#include "probes/probe_rays.h"
#include "probes/interpolation.h"
#include "shading/sh_light.h"

using namespace transgi;
using namespace engine;

namespace {

// A field of random probes (depth moments, SH, a few unusable) over [lo, hi].
struct RandomField {
  probes::ProbeGrid grid;
  probes::MapLayout layout{16, 8};
  std::vector<probes::ProbeMapState> states;
  std::vector<std::uint8_t> usable;
  std::vector<float> sh;
  probes::InterpolationSettings interpolation;

  RandomField(glm::vec3 lo, glm::vec3 hi, glm::ivec3 dims, std::uint64_t seed) {
    grid = probes::ProbeGrid{lo, hi, dims};
    math::Pcg32 rng(seed, 3);
    const int count = grid.count();
    const float unit = grid.min_spacing();
    grid.offsets.resize(static_cast<std::size_t>(count));
    for (auto& o : grid.offsets) o = 0.2f * unit * glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
    states.resize(static_cast<std::size_t>(count));
    usable.resize(static_cast<std::size_t>(count));
    sh.resize(static_cast<std::size_t>(count) * 75);
    for (int q = 0; q < count; ++q) {
      auto& st = states[static_cast<std::size_t>(q)];
      st.depth.reset(layout.texel_count(), unit);
      for (int t = 0; t < layout.texel_count(); ++t)
        st.depth.set(static_cast<std::size_t>(t), unit * (0.3f + 2.0f * rng.next_float()), 0.02f * unit * unit * rng.next_float());
      usable[static_cast<std::size_t>(q)] = rng.next_float() < 0.1f ? 0 : 1;
      // A positive DC term and smaller higher bands, as light has.
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 25; ++k)
          sh[static_cast<std::size_t>(q) * 75 + c * 25 + k] = k == 0 ? 1.0f + rng.next_float() : 0.3f * (rng.next_float() - 0.5f);
    }
  }
  [[nodiscard]] probes::ProbeFeedbackSource source() const {
    return {&grid, layout, &states, sh, usable, interpolation};
  }
  // ProbeField::irradiance's arithmetic.
  [[nodiscard]] glm::vec3 irradiance(const glm::vec3& p, const glm::vec3& n) const {
    const probes::InterpolationResult r = probes::interpolate_probes(grid, layout, states, p, n, interpolation, usable);
    float L[75] = {};
    for (std::size_t i = 0; i < 8; ++i) {
      if (r.weights[i] == 0.0f) continue;
      for (int k = 0; k < 75; ++k) L[k] += r.weights[i] * sh[static_cast<std::size_t>(r.probes[i]) * 75 + k];
    }
    return shading::sh_irradiance(L, n);
  }
};

// A sky brighter towards +Y with a hot spot, so importance sampling matters.
scene::Environment test_sky() {
  image::ImageRGB img(64, 32);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const float v = (static_cast<float>(y) + 0.5f) / static_cast<float>(img.height);
      img.at(x, y) = glm::vec3(0.2f, 0.3f, 0.5f) * (1.5f - v) + ((x == 40 && y == 9) ? glm::vec3(200.0f, 180.0f, 150.0f) : glm::vec3(0.0f));
    }
  glm::mat4 m = glm::rotate(glm::mat4(1.0f), 0.7f, glm::vec3(0, 1, 0));
  return scene::Environment(std::move(img), 1.3f, m);
}

std::vector<render::PunctualInstance> test_punctual() {
  std::vector<render::PunctualInstance> out;
  scene::PunctualLight point;
  point.type = scene::PunctualLight::Type::Point;
  point.color = {1.0f, 0.9f, 0.8f};
  point.intensity = 20.0f;
  point.range = 6.0f;
  out.push_back({point, glm::vec3(0.5f, 1.8f, 0.2f), glm::vec3(0, 0, -1), 0.0f});
  scene::PunctualLight spot;
  spot.type = scene::PunctualLight::Type::Spot;
  spot.intensity = 40.0f;
  spot.inner_cone_angle = 0.3f;
  spot.outer_cone_angle = 0.6f;
  out.push_back({spot, glm::vec3(-1.0f, 2.2f, 0.5f), glm::normalize(glm::vec3(0.3f, -1.0f, 0.1f)), 0.0f});
  scene::PunctualLight sun;
  sun.type = scene::PunctualLight::Type::Directional;
  sun.intensity = 3.0f;
  out.push_back({sun, glm::vec3(0.0f), glm::normalize(glm::vec3(-0.4f, -1.0f, -0.3f)), 0.05f});
  return out;
}

// The sample level lit by test_punctual, a 4 x 3 x 4 probe grid over it,
// and a probe-ray batch from `tracing` along m Fibonacci directions: the
// probe-kernel tests' setting.
struct SampleLevelRays {
  eval::LoadedScene loaded = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  const rt::RtScene& scene = loaded.app->world().resource<rt::RtScene>();
  const render::LightSet lights{scene, test_punctual(), nullptr};
  const probes::ProbeGrid grid = probes::ProbeGrid::centred_in(scene.bounds_min(), scene.bounds_max(), glm::ivec3(4, 3, 4));
  std::vector<glm::vec3> directions, origins;
  std::vector<int> tracing;
  // Every probe q with traced(q) traces m rays.
  template <class Traced>
  SampleLevelRays(int m, Traced traced) : directions(probes::spherical_fibonacci(m)) {
    for (int q = 0; q < grid.count(); ++q)
      if (traced(q)) {
        tracing.push_back(q);
        origins.push_back(grid.position(q));
      }
  }
};

struct Compared {
  int rays = 0, hits = 0, shadowed = 0, lit = 0, outside = 0;
  int flag_mismatch = 0, value_mismatch = 0;
  double mean_cpu = 0, mean_gpu = 0, worst = 0;
};

}  // namespace

// Every ray's result to 1e-3 relative (+ 1e-5 absolute) in position,
// normal, emission and radiance, and the same flags. A float CDF on the
// device against the CPU's double one can pick a neighbouring bin for a
// random number within rounding of a border, and a shadow ray that grazes
// an edge can be blocked for one tracer and not the other: at most 0.5 % of
// the rays may differ.
TEST(VulkanProbeShading, EqualsTheCpuStagesOnTheSampleLevelWithEveryKindOfLight) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  std::string why;
  if (!transgi::gpu::VulkanProbeShading::supported(*ctx, &why)) GTEST_SKIP() << why;
  eval::LoadedScene loaded = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
  const rt::RtScene& scene = loaded.app->world().resource<rt::RtScene>();
  const scene::Environment sky = test_sky();
  const render::LightSet lights(scene, test_punctual(), &sky);
  ASSERT_EQ(lights.groups(), lights.emissive_triangle_count() > 0 ? 3 : 2);

  const glm::vec3 lo = scene.bounds_min(), hi = scene.bounds_max();
  const glm::vec3 mid = 0.5f * (lo + hi);
  // The inner field holds the lower half of the scene (its floor and the
  // walls' lower halves), the outer all of it.
  const glm::vec3 margin(0.01f);
  const RandomField inner(lo - margin, glm::vec3(hi.x, mid.y, hi.z) + margin, glm::ivec3(4, 3, 4), 5);
  const RandomField outer(lo, hi, glm::ivec3(3, 3, 3), 6);
  const probes::ProbeFeedbackSource self_source = inner.source(), outer_source = outer.source();

  // 300 "probes" at random points, each shooting the same 20 random directions.
  math::Pcg32 rng(21, 4);
  const int probe_count = 300, m = 20, n = probe_count * m;
  std::vector<glm::vec3> origins, directions;
  std::vector<int> probe_ids;
  for (int j = 0; j < probe_count; ++j) {
    origins.push_back(glm::mix(lo + 0.1f * (hi - lo), hi - 0.1f * (hi - lo), glm::vec3{rng.next_float(), rng.next_float(), rng.next_float()}));
    probe_ids.push_back(3 * j + 1);
  }
  for (int i = 0; i < m; ++i)
    directions.push_back(glm::normalize(glm::vec3{rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f} + 1e-4f));
  const std::uint64_t seed = 0x1234'5678'9abcULL, sample = 42;

  transgi::gpu::VulkanProbeShading shading(*ctx);
  engine::gpu::GpuRayTracer tracer(*ctx);
  std::vector<probes::ProbeRayHit> got;
  ASSERT_TRUE(shading.shade(scene, lights, tracer, origins, probe_ids, directions, seed, sample, &self_source, &outer_source, got));
  ASSERT_EQ(got.size(), static_cast<std::size_t>(n));

  // The CPU stages on the same rays, whose hits the same traversal finds.
  std::vector<rt::Ray> rays;
  std::vector<std::uint64_t> items;
  for (int j = 0; j < probe_count; ++j)
    for (int i = 0; i < m; ++i) {
      rays.push_back(rt::Ray{origins[static_cast<std::size_t>(j)], directions[static_cast<std::size_t>(i)]});
      items.push_back(static_cast<std::uint64_t>(probe_ids[static_cast<std::size_t>(j)]) * 4096 + static_cast<std::uint64_t>(i));
    }
  std::vector<rt::Hit> hits(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  tracer.intersect(scene, rays, hits, found);
  Compared c;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    math::Pcg32 r = math::make_rng(seed, items[k], sample);
    const probes::PendingProbeRay pending = probes::begin_probe_ray(scene, lights, rays[k].direction, found[k] ? &hits[k] : nullptr, r);
    const bool blocked = pending.needs_shadow && scene.occluded(pending.shadow);
    bool was_outside = false;
    const probes::ProbeRayHit want = probes::finish_probe_ray(pending, blocked, [&](const glm::vec3& p, const glm::vec3& nrm, const glm::vec3&) {
      was_outside = glm::any(glm::lessThan(p, inner.grid.min)) || glm::any(glm::greaterThan(p, inner.grid.max));
      return was_outside ? outer.irradiance(p, nrm) : inner.irradiance(p, nrm);
    });
    const probes::ProbeRayHit& g = got[k];
    ++c.rays;
    c.hits += want.hit;
    c.shadowed += pending.needs_shadow && blocked;
    c.lit += pending.needs_shadow && !blocked;
    c.outside += want.hit && pending.takes_feedback && was_outside;
    if (g.hit != want.hit || g.back_face != want.back_face || g.saw_light != want.saw_light) {
      if (c.flag_mismatch < 5)
        std::printf("ray %d: hit, back face, saw light: cpu %d %d %d, gpu %d %d %d\n", i, want.hit, want.back_face,
                    want.saw_light, g.hit, g.back_face, g.saw_light);
      ++c.flag_mismatch;
      continue;
    }
    double err = 0;
    auto check = [&](const glm::vec3& a, const glm::vec3& b) {
      for (int j = 0; j < 3; ++j) {
        const double e = std::abs(double(a[j]) - b[j]) / (1e-3 * std::max(std::abs(double(b[j])), 1e-2));
        if (std::isfinite(b[j]) || std::isfinite(a[j])) err = std::max(err, std::isfinite(e) ? e : 1e9);
      }
    };
    if (want.hit) {
      check(g.position, want.position);
      check(g.normal, want.normal);
      err = std::max(err, std::abs(double(g.distance) - want.distance) / (1e-3 * std::max(double(want.distance), 1e-2)));
    }
    check(g.emitted, want.emitted);
    check(g.radiance, want.radiance);
    c.worst = std::max(c.worst, err);
    if (err > 1.0) {
      if (c.value_mismatch < 5)
        std::printf("ray %d: radiance cpu (%g %g %g) gpu (%g %g %g), emitted cpu (%g %g %g) gpu (%g %g %g)\n", i, want.radiance.r,
                    want.radiance.g, want.radiance.b, g.radiance.r, g.radiance.g, g.radiance.b, want.emitted.r, want.emitted.g,
                    want.emitted.b, g.emitted.r, g.emitted.g, g.emitted.b);
      ++c.value_mismatch;
    }
    c.mean_cpu += (want.radiance.r + want.radiance.g + want.radiance.b + want.emitted.r + want.emitted.g + want.emitted.b) / n;
    c.mean_gpu += (g.radiance.r + g.radiance.g + g.radiance.b + g.emitted.r + g.emitted.g + g.emitted.b) / n;
  }
  std::printf("probe shading: %d rays, %d hits, %d lit and %d shadowed light samples, %d lit by the outer field; "
              "%d flag and %d value mismatches; largest error %.3g of the tolerance; mean radiance + emission cpu %.6g gpu %.6g\n",
              c.rays, c.hits, c.lit, c.shadowed, c.outside, c.flag_mismatch, c.value_mismatch, c.worst, c.mean_cpu, c.mean_gpu);
  EXPECT_GT(c.hits, n / 2) << "most rays should hit the level";
  EXPECT_GT(c.lit, n / 20) << "the light samples should often be unoccluded";
  EXPECT_GT(c.shadowed, n / 50);
  EXPECT_GT(c.outside, n / 20) << "some hits should take the outer field's light";
  EXPECT_LT(c.outside, c.hits - n / 20) << "some hits should take the inner field's light";
  EXPECT_LE(c.flag_mismatch + c.value_mismatch, n / 200)
      << "expected at most 0.5 % of rays to differ, got " << c.flag_mismatch << " flag and " << c.value_mismatch << " value mismatches";
  EXPECT_NEAR(c.mean_gpu, c.mean_cpu, 2e-3 * c.mean_cpu) << "expected the mean radiance within 0.2 %";
}

namespace {
// A device whose largest storage buffer cannot hold the sample level's
// triangles and texels; null, with *why, where none can be made.
std::shared_ptr<engine::gpu::VulkanContext> capped_device(std::string* why) {
  engine::gpu::GpuOptions options;
  options.storage_buffer_range_cap = 64 * 1024;
  return std::shared_ptr<engine::gpu::VulkanContext>(engine::gpu::VulkanContext::create(options, why));
}
}  // namespace

// A device whose largest buffer cannot hold the level's shading data: the
// kernels throw, naming what did not fit, and the plugin runs that frame and
// every later one on the CPU backend whole, saying why: the frame is the CPU
// backend's own, bit for bit (the device's first stage threw before any
// field changed).
TEST(VulkanProbeShading, ASceneTooBigForTheDeviceRunsTheWholeFrameOnTheCpuBackend) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  std::string why;
  const std::shared_ptr<engine::gpu::VulkanContext> ctx = capped_device(&why);
  ASSERT_TRUE(ctx) << why;
  if (!transgi::gpu::VulkanProbeShading::supported(*ctx, &why)) GTEST_SKIP() << why;
  const std::string level = std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf";
  {
    transgi::gpu::VulkanProbeKernels kernels(ctx);
    eval::LoadedScene loaded = eval::load_scene(level, "", 2);
    const rt::RtScene& scene = loaded.app->world().resource<rt::RtScene>();
    const render::LightSet lights(scene, test_punctual(), nullptr);
    const std::vector<glm::vec3> origins{0.5f * (scene.bounds_min() + scene.bounds_max())}, directions{glm::vec3(0, -1, 0)};
    const std::vector<int> probe_ids{0};
    const probes::ProbeGrid grid;
    probes::ProbeFeedbackSource self;
    self.grid = &grid;
    self.lit = false;
    std::vector<probes::ProbeRayHit> out;
    try {
      kernels.shade_probe_rays(scene, lights, origins, probe_ids, directions, 1, 1, self, nullptr,
                               [&](int, int, const probes::ProbeRayHit& h) { out.push_back(h); });
      ADD_FAILURE() << "expected the kernels to throw engine::gpu::GpuError";
    } catch (const engine::gpu::GpuError& e) {
      EXPECT_NE(std::string(e.what()).find("largest storage buffer"), std::string::npos) << e.what();
      std::printf("declined: %s\n", e.what());
    }
    EXPECT_TRUE(out.empty());
  }
  const auto run = [&](runtime::Backend backend, std::shared_ptr<engine::gpu::VulkanContext> host) {
    eval::TransgiRunOptions t;
    t.frames = 3;
    t.progress = false;
    t.settings.backend = backend;
    t.settings.direct_spp = 0;
    t.settings.probes.map = probes::MapLayout{16, 8};
    t.settings.probes.rays_per_probe = 32;
    t.placement.mode = runtime::ProbeVolumeMode::Scene;
    t.placement.scene_dims = glm::ivec3(4);
    t.host_gpu = std::move(host);
    eval::LoadedScene scene = eval::load_scene(level, "", 2);
    return eval::run_transgi(scene, std::make_shared<const model::TransferModel>(), 32, 18, t);
  };
  const eval::MethodRun capped = run(runtime::Backend::Vulkan, ctx), cpu = run(runtime::Backend::Cpu, nullptr);
  gpu_test::expect_cpu_fallback_frame(capped.backend, capped.gi, cpu.backend, cpu.gi);
}

// The same device with the probes frozen (an editor's still view): the
// first device work of a frame is then the real-time G-buffer's, in
// render_gi, which must fall back as the probe update does: the CPU
// backend makes the image whole, says why, and its full frame is the CPU
// backend's own, bit for bit.
TEST(VulkanProbeShading, ASceneTooBigForTheDeviceWithTheProbesFrozenRendersOnTheCpuBackend) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  std::string why;
  const std::shared_ptr<engine::gpu::VulkanContext> ctx = capped_device(&why);
  ASSERT_TRUE(ctx) << why;
  if (!transgi::gpu::VulkanProbeShading::supported(*ctx, &why)) GTEST_SKIP() << why;
  const auto run = [&](runtime::Backend backend, std::shared_ptr<engine::gpu::VulkanContext> host) {
    eval::TransgiRunOptions t;
    t.frames = 3;
    t.progress = false;
    t.settings = runtime::realtime_preset();
    t.settings.backend = backend;
    t.settings.freeze_probes = true;
    t.placement.mode = runtime::ProbeVolumeMode::Scene;
    t.placement.scene_dims = glm::ivec3(4);
    t.host_gpu = std::move(host);
    eval::LoadedScene scene = eval::load_scene(std::string(TRANSGI_CONTENT_DIR) + "/levels/living_room/scene.gltf", "", 2);
    return eval::run_transgi(scene, std::make_shared<const model::TransferModel>(), 32, 18, t);
  };
  const eval::MethodRun capped = run(runtime::Backend::Vulkan, ctx), cpu = run(runtime::Backend::Cpu, nullptr);
  EXPECT_EQ(capped.backend.rfind("cpu; the CPU backend runs the frame (scene too large): ", 0), 0u) << capped.backend;
  EXPECT_EQ(cpu.backend, "cpu");
  ASSERT_GT(gpu_test::mean_rgb(cpu.full), 1e-3) << "the frame should not be black";
  std::size_t differ = 0;
  for (std::size_t i = 0; i < cpu.full.pixels.size(); ++i) differ += capped.full.pixels[i] != cpu.full.pixels[i] ? 1 : 0;
  EXPECT_EQ(differ, 0u) << "expected the CPU backend's frame exactly";
}

// The raster's points made on the device from the probe rays' hits
// (probe_points.comp) instead of sent from the host: a grid of probes in the
// sample level shades its rays on the device, the host builds each probe's
// points from the hits as ProbeField does (and drops one probe's, as it does
// for a probe that moved); the Vulkan backend's raster, accumulation and
// projection then equal the CPU backend's on those points (SH within 1e-3 of
// the largest, the depth guard's counts within 0.1 %), and the points do not
// go up. With one point missing the points no longer match the rays: they go
// up from the host (at least 64 bytes each), with the same result. Then the
// hits come back brief (set_brief_hits, the default): 44 bytes a ray fewer,
// the same SH from the device's points, and host points that are not the
// rays refused.
TEST(VulkanProbeKernels, ThePointsAreMadeOnTheDeviceFromTheShadedRays) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  OWN_PROBE_KERNELS_OR_SKIP(own);
  const std::shared_ptr<engine::gpu::VulkanContext>& ctx = own.ctx;
  const std::shared_ptr<transgi::gpu::VulkanProbeKernels>& kernels = own.kernels;
  const int m = 32;
  const SampleLevelRays level(m, [](int q) { return q % 5 != 3; });  // a few probes not traced this frame
  const auto& [loaded, scene, lights, grid, directions, origins, tracing] = level;
  const probes::MapLayout layout{16, 8};
  const int count = grid.count();
  probes::ProbeFeedbackSource self;
  self.grid = &grid;
  self.layout = layout;
  self.lit = false;
  std::vector<std::vector<probes::ShadedPoint>> points(static_cast<std::size_t>(count));
  std::vector<std::vector<probes::ProbeRayHit>> hits(tracing.size());
  kernels->set_brief_hits(false);  // whole hits: the CPU's points below are built from them
  engine::gpu::GpuTraffic before_shading = ctx->traffic();
  kernels->shade_probe_rays(scene, lights, origins, tracing, directions, 7, 1, self, nullptr,
                            [&](int j, int, const probes::ProbeRayHit& h) { hits[static_cast<std::size_t>(j)].push_back(h); });
  const engine::gpu::GpuTraffic whole = ctx->traffic() - before_shading;
  for (std::size_t j = 0; j < tracing.size(); ++j)
    for (std::size_t i = 0; i < hits[j].size(); ++i) {
      const probes::ProbeRayHit& h = hits[j][i];
      probes::ShadedPoint sp;
      sp.direction = directions[i];
      sp.distance = h.distance;
      sp.position = h.position;
      sp.radiance = h.radiance;
      sp.normal = h.normal;
      points[static_cast<std::size_t>(tracing[j])].push_back(sp);
    }
  points[static_cast<std::size_t>(tracing[2])].clear();  // a probe that moved: its points dropped
  // Each probe's own depth from its points, as the field makes it.
  std::vector<probes::ProbeMapState> depth_of(static_cast<std::size_t>(count));
  std::vector<const probes::DepthMap*> own_depth;
  for (int q = 0; q < count; ++q) {
    probes::ProbeMapState& st = depth_of[static_cast<std::size_t>(q)];
    st.reset(layout.texel_count(), grid.min_spacing());
    probes::update_own_depth(st, layout, points[static_cast<std::size_t>(q)], probes::AccumulationSettings{});
    own_depth.push_back(&st.depth);
  }
  std::vector<int> batch;
  for (int q = 0; q < count; ++q)
    if (q % 2 == 0) batch.push_back(q);
  const probes::MapProjector projector(layout);
  const probes::SharingSettings sharing;
  const probes::AccumulationSettings accumulation;
  const auto update = [&](probes::ProbeKernels& k, const std::vector<std::vector<probes::ShadedPoint>>& pts,
                          std::vector<float>& sh, probes::SharingStats& stats) {
    std::vector<probes::ProbeMapState> states(batch.size());
    std::vector<probes::ProbeMapState*> ptrs;
    for (auto& s : states) {
      s.reset(layout.texel_count(), grid.min_spacing());
      ptrs.push_back(&s);
    }
    std::vector<std::uint8_t> changed(batch.size());
    sh.assign(batch.size() * 75, 0.0f);
    probes::ShareAccumulateTimes times;
    const engine::gpu::GpuTraffic before = ctx->traffic();
    stats = k.share_accumulate_project(grid, projector, pts, own_depth, sharing, batch, ptrs, nullptr, accumulation, changed, sh, times);
    return ctx->traffic() - before;
  };
  probes::CpuProbeKernels cpu;
  std::vector<float> cpu_sh, device_sh, host_sh;
  probes::SharingStats cpu_stats, device_stats, host_stats;
  update(cpu, points, cpu_sh, cpu_stats);
  update(*kernels, points, device_sh, device_stats);  // the first also sends the kernels' constant tables
  const engine::gpu::GpuTraffic made = update(*kernels, points, device_sh, device_stats);
  // One point fewer: the host's points are not the rays' any more.
  std::vector<std::vector<probes::ShadedPoint>> fewer = points;
  fewer[static_cast<std::size_t>(tracing[0])].pop_back();
  std::vector<float> cpu_fewer_sh;
  probes::SharingStats cpu_fewer_stats;
  update(cpu, fewer, cpu_fewer_sh, cpu_fewer_stats);
  const engine::gpu::GpuTraffic sent = update(*kernels, fewer, host_sh, host_stats);
  std::size_t point_count = 0;
  for (const auto& p : fewer) point_count += p.size();
  std::printf("%zu points: %llu bytes up when made on the device, %llu when sent\n", point_count,
              static_cast<unsigned long long>(made.host_to_device_bytes), static_cast<unsigned long long>(sent.host_to_device_bytes));
  // (Made on the device, each traced probe's first point's index goes up instead: 4 bytes.)
  EXPECT_GE(sent.host_to_device_bytes + tracing.size() * 4, made.host_to_device_bytes + point_count * 64);
  const auto expect_near = [](const std::vector<float>& want, const std::vector<float>& got, const probes::SharingStats& ws,
                              const probes::SharingStats& gs, const char* what) {
    float largest = 0.0f, worst = 0.0f;
    for (std::size_t k = 0; k < want.size(); ++k) {
      largest = std::max(largest, std::abs(want[k]));
      worst = std::max(worst, std::abs(got[k] - want[k]));
    }
    std::printf("%s: largest SH coefficient %.4g, largest difference %.3g; accepted %zu (CPU %zu), rejected %zu (CPU %zu)\n", what,
                largest, worst, gs.accepted, ws.accepted, gs.rejected_by_guard, ws.rejected_by_guard);
    EXPECT_GT(largest, 0.0f) << what;
    EXPECT_LE(worst, 1e-3f * largest) << what;
    EXPECT_NEAR(static_cast<double>(gs.accepted), static_cast<double>(ws.accepted), 1e-3 * ws.accepted + 1) << what;
    EXPECT_NEAR(static_cast<double>(gs.rejected_by_guard), static_cast<double>(ws.rejected_by_guard), 1e-3 * ws.rejected_by_guard + 1)
        << what;
  };
  expect_near(cpu_sh, device_sh, cpu_stats, device_stats, "points made on the device");
  expect_near(cpu_fewer_sh, host_sh, cpu_fewer_stats, host_stats, "points sent from the host");

  // The same rays again, their hits brief.
  kernels->set_brief_hits(true);
  std::atomic<std::size_t> brief_rays{0};  // the probes' rays are handed over from several threads
  before_shading = ctx->traffic();
  kernels->shade_probe_rays(scene, lights, origins, tracing, directions, 7, 1, self, nullptr,
                            [&](int j, int i, const probes::ProbeRayHit& h) {
                              const probes::ProbeRayHit& w = hits[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)];
                              EXPECT_EQ(h.hit, w.hit);
                              EXPECT_EQ(h.distance, w.distance);
                              EXPECT_EQ(h.emitted, w.emitted);
                              ++brief_rays;
                            });
  const engine::gpu::GpuTraffic brief = ctx->traffic() - before_shading;
  std::printf("%zu rays: %llu bytes back with whole hits, %llu brief\n", brief_rays.load(),
              static_cast<unsigned long long>(whole.device_to_host_bytes), static_cast<unsigned long long>(brief.device_to_host_bytes));
  EXPECT_EQ(brief_rays.load(), tracing.size() * static_cast<std::size_t>(m));
  EXPECT_GE(whole.device_to_host_bytes, brief.device_to_host_bytes + brief_rays.load() * 44);
  std::vector<float> brief_sh;
  probes::SharingStats brief_stats;
  update(*kernels, points, brief_sh, brief_stats);
  expect_near(cpu_sh, brief_sh, cpu_stats, brief_stats, "points made on the device, hits brief");
  EXPECT_THROW(update(*kernels, fewer, brief_sh, brief_stats), std::logic_error);
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// The batch's own depth maps updated on the device (probe_own_depth.comp)
// in the field's store, from the probe rays' hits the shading left there,
// while the host updates its own copy (probes::update_own_depth): over four
// frames of the sample level's probe rays (64 rays into 32-texel maps, so
// that texels take several rays a frame, in order), the device's copy of
// every batch probe equals the host's bit for bit, the other probes' stay as
// they were, and no updated map is sent up again (the store holds the
// version the host stamped).
TEST(VulkanProbeKernels, TheOwnDepthIsUpdatedOnTheDeviceBitForBitAndNotSentUp) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  OWN_PROBE_KERNELS_OR_SKIP(own);
  const std::shared_ptr<transgi::gpu::VulkanProbeKernels>& kernels = own.kernels;
  const SampleLevelRays level(64, [](int) { return true; });
  const auto& [loaded, scene, lights, grid, directions, origins, tracing] = level;
  const probes::MapLayout layout{8, 4};
  const int count = grid.count();
  const std::size_t texels = static_cast<std::size_t>(layout.texel_count());
  std::vector<probes::ProbeMapState> states(static_cast<std::size_t>(count));
  for (auto& st : states) st.reset(layout.texel_count(), grid.min_spacing());
  std::vector<const probes::DepthMap*> own_depth;
  for (const auto& st : states) own_depth.push_back(&st.depth);
  std::unique_ptr<probes::ProbeMapStore> store = kernels->make_map_store(layout, count);
  auto* maps = dynamic_cast<transgi::gpu::VulkanMapStore*>(store.get());
  ASSERT_NE(maps, nullptr);
  probes::ProbeFeedbackSource self;
  self.grid = &grid;
  self.layout = layout;
  self.lit = false;
  const probes::MapProjector projector(layout);
  const probes::SharingSettings sharing;
  const probes::AccumulationSettings accumulation;
  std::size_t collisions = 0;
  for (int frame = 0; frame < 4; ++frame) {
    // Every probe traces; a third of them (another third each frame) update.
    std::vector<std::vector<probes::ShadedPoint>> points(static_cast<std::size_t>(count));
    kernels->shade_probe_rays(scene, lights, origins, tracing, directions, 7, static_cast<std::uint64_t>(frame + 1), self, nullptr,
                              [&](int j, int i, const probes::ProbeRayHit& h) {
                                probes::ShadedPoint sp;
                                sp.direction = directions[static_cast<std::size_t>(i)];
                                sp.distance = h.distance;
                                points[static_cast<std::size_t>(tracing[static_cast<std::size_t>(j)])].push_back(sp);
                              });
    std::vector<int> batch;
    std::vector<probes::ProbeMapState*> batch_states;
    for (int q = 0; q < count; ++q)
      if (q % 3 != frame % 3) {
        batch.push_back(q);
        batch_states.push_back(&states[static_cast<std::size_t>(q)]);
      }
    if (frame == 0) {  // texels that take more than one ray: the update's order matters
      std::vector<int> per(texels, 0);
      for (const auto& pt : points[0])
        if (std::isfinite(pt.distance)) collisions += ++per[static_cast<std::size_t>(layout.texel_of(pt.direction))] > 1;
    }
    const std::vector<probes::DepthMap> before = [&] {
      std::vector<probes::DepthMap> d;
      for (const auto& st : states) d.push_back(st.depth);
      return d;
    }();
    std::vector<std::uint8_t> changed(batch.size());
    std::vector<float> sh(batch.size() * 75);
    probes::ShareAccumulateTimes times;
    kernels->share_accumulate_project(grid, projector, points, own_depth, sharing, batch, batch_states, store.get(), accumulation,
                                      changed, sh, times);
    std::vector<std::uint32_t> device(static_cast<std::size_t>(count) * texels);
    maps->depth().download(std::span<std::uint32_t>(device));
    std::size_t differ = 0, updated = 0;
    for (int q = 0; q < count; ++q) {
      const probes::DepthMap& host = states[static_cast<std::size_t>(q)].depth;
      for (std::size_t t = 0; t < texels; ++t) {
        const std::uint32_t want = std::uint32_t{host.texels[t].mean} | std::uint32_t{host.texels[t].variance} << 16;
        differ += device[static_cast<std::size_t>(q) * texels + t] != want;
        const probes::DepthMap::Texel& was = before[static_cast<std::size_t>(q)].texels[t];
        updated += was.mean != host.texels[t].mean || was.variance != host.texels[t].variance;
      }
    }
    maps->stage_depth(own_depth);
    std::printf("frame %d: %zu batch probes, %zu texels updated, %zu differ from the host's, %zu maps to send again\n", frame,
                batch.size(), updated, differ, maps->depth_maps_staged());
    EXPECT_EQ(differ, 0u) << "frame " << frame;
    EXPECT_GT(updated, texels) << "frame " << frame;
    EXPECT_EQ(maps->depth_maps_staged(), 0u) << "frame " << frame << ": the device holds every map the host has";
    for (int q = frame % 3; q < count; q += 3)  // not in the batch: as it was
      for (std::size_t t = 0; t < texels; ++t)
        ASSERT_EQ(states[static_cast<std::size_t>(q)].depth.texels[t].mean, before[static_cast<std::size_t>(q)].texels[t].mean)
            << "probe " << q << " frame " << frame;
  }
  EXPECT_GT(collisions, 0u) << "no texel took two rays: the test would not see the update's order";
  EXPECT_EQ(own.ctx->validation_errors(), 0);
}

// The probe rays and the light they carry into the probes in one submission
// (shade_and_light, for a frame whose batch is known before its rays)
// against the same two stages in two submissions, on the same device over
// three frames of the sample level's probe rays, each path with its own
// field maps in its own store: the same hits handed to the consumer, the
// same SH, change flags and depth maps, bit for bit, in one submission
// instead of two. From the second frame the rays' bounce light reads each
// path's field (its SH, and its depth maps from its store, which both the
// rays and the raster stage in the one submission); on the third, an
// untraced probe's depth map changed on the host must reach the rays.
TEST(VulkanProbeKernels, TheRaysAndTheirLightInOneSubmissionEqualTheTwoStages) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  OWN_PROBE_KERNELS_OR_SKIP(own);
  const std::shared_ptr<engine::gpu::VulkanContext>& ctx = own.ctx;
  const std::shared_ptr<transgi::gpu::VulkanProbeKernels>& kernels = own.kernels;
  const int m = 48;
  const SampleLevelRays level(m, [](int q) { return q % 4 != 1; });
  const auto& [loaded, scene, lights, grid, directions, origins, tracing] = level;
  const probes::MapLayout layout{16, 8};
  const int count = grid.count();
  const std::size_t texels = static_cast<std::size_t>(layout.texel_count());
  const probes::MapProjector projector(layout);
  const probes::SharingSettings sharing;
  const probes::AccumulationSettings accumulation;
  struct Path {
    std::vector<probes::ProbeMapState> states;
    std::vector<const probes::DepthMap*> own_depth;
    std::unique_ptr<probes::ProbeMapStore> store;
    std::vector<float> sh;
    std::vector<std::uint8_t> changed;
    std::vector<probes::ProbeRayHit> hits;
    // The field the rays' bounce light reads from the second frame on (its
    // depth maps from the store: staged by both stages of one submission).
    std::vector<float> field_sh;
    std::vector<std::uint8_t> usable;
    std::uint64_t bytes_back = 0;
  };
  const auto make_path = [&] {
    Path p;
    p.states.resize(static_cast<std::size_t>(count));
    for (auto& st : p.states) st.reset(layout.texel_count(), grid.min_spacing());
    for (const auto& st : p.states) p.own_depth.push_back(&st.depth);
    p.store = kernels->make_map_store(layout, count);
    p.field_sh.assign(static_cast<std::size_t>(count) * 75, 0.0f);
    p.usable.assign(static_cast<std::size_t>(count), 1);
    return p;
  };
  Path two = make_path(), one = make_path();
  {  // The scene's first upload and BLAS builds, outside the counts.
    probes::ProbeFeedbackSource self;
    self.grid = &grid;
    self.layout = layout;
    self.lit = false;
    kernels->shade_probe_rays(scene, lights, origins, tracing, directions, 7, 99, self, nullptr, [](int, int, const probes::ProbeRayHit&) {});
  }
  for (int frame = 0; frame < 3; ++frame) {
    std::vector<int> batch;
    for (const int q : tracing)
      if (q % 3 != frame) batch.push_back(q);
    const auto run = [&](Path& p, bool together) {
      std::vector<std::vector<probes::ShadedPoint>> points(static_cast<std::size_t>(count));
      p.hits.assign(tracing.size() * static_cast<std::size_t>(m), probes::ProbeRayHit{});
      const probes::ProbeRayConsumer consume = [&](int j, int i, const probes::ProbeRayHit& h) {
        p.hits[static_cast<std::size_t>(j) * m + static_cast<std::size_t>(i)] = h;
        probes::ShadedPoint sp;
        sp.direction = directions[static_cast<std::size_t>(i)];
        sp.distance = h.distance;
        points[static_cast<std::size_t>(tracing[static_cast<std::size_t>(j)])].push_back(sp);
      };
      std::vector<probes::ProbeMapState*> states;
      for (const int q : batch) states.push_back(&p.states[static_cast<std::size_t>(q)]);
      p.sh.assign(batch.size() * 75, 0.0f);
      p.changed.assign(batch.size(), 0);
      probes::ShareAccumulateTimes times;
      probes::ProbeFeedbackSource self;
      self.grid = &grid;
      self.layout = layout;
      self.states = &p.states;
      self.sh = p.field_sh;
      self.usable = p.usable;
      self.maps = p.store.get();
      self.lit = frame > 0;
      const engine::gpu::GpuTraffic before = ctx->traffic();
      if (together) {
        probes::ProbeRayRequest rays{&scene, &lights, origins, tracing, directions, 7, static_cast<std::uint64_t>(frame + 1), &self, nullptr};
        rays.emission = frame != 1;  // the second frame's consumer reads no emission
        probes::ProbeLightRequest light{&grid,    &projector, &points,   &p.own_depth, &sharing, batch, states,
                                        p.store.get(), &accumulation, p.changed, p.sh, &times};
        kernels->shade_and_light(rays, consume, light);
      } else {
        kernels->shade_probe_rays(scene, lights, origins, tracing, directions, 7, static_cast<std::uint64_t>(frame + 1), self, nullptr,
                                  consume);
        kernels->share_accumulate_project(grid, projector, points, p.own_depth, sharing, batch, states, p.store.get(), accumulation,
                                          p.changed, p.sh, times);
      }
      const engine::gpu::GpuTraffic spent = ctx->traffic() - before;
      p.bytes_back = spent.device_to_host_bytes;
      const std::uint64_t submissions = spent.submissions;
      for (std::size_t k = 0; k < batch.size(); ++k)
        std::copy_n(p.sh.data() + k * 75, 75, p.field_sh.data() + static_cast<std::size_t>(batch[k]) * 75);
      return submissions;
    };
    if (frame == 2)  // an untraced probe's depth changed on the host: it must go up before the rays read it
      for (Path* p : {&two, &one}) {
        probes::DepthMap& d = p->states[1].depth;
        for (std::size_t t = 0; t < texels; ++t) d.set(t, 0.05f * grid.min_spacing(), 0.0f);
        d.stamp_version();
      }
    const std::uint64_t two_submissions = run(two, false), one_submission = run(one, true);
    std::size_t hits_differ = 0, depth_differ = 0, sh_differ = 0;
    std::size_t emitting = 0;
    for (std::size_t k = 0; k < two.hits.size(); ++k) {
      emitting += two.hits[k].emitted != glm::vec3(0.0f);
      hits_differ += two.hits[k].hit != one.hits[k].hit || two.hits[k].distance != one.hits[k].distance ||
                     (frame != 1 && two.hits[k].emitted != one.hits[k].emitted) || two.hits[k].saw_light != one.hits[k].saw_light ||
                     (frame == 1 && one.hits[k].emitted != glm::vec3(0.0f));
    }
    // Without the emission, 12 bytes a ray fewer come back; else the same bytes.
    EXPECT_EQ(two.bytes_back - one.bytes_back, frame == 1 ? 12u * two.hits.size() : 0u) << "frame " << frame;
    for (int q = 0; q < count; ++q)
      for (std::size_t t = 0; t < texels; ++t) {
        const auto& a = two.states[static_cast<std::size_t>(q)].depth.texels[t];
        const auto& b = one.states[static_cast<std::size_t>(q)].depth.texels[t];
        depth_differ += a.mean != b.mean || a.variance != b.variance;
      }
    for (std::size_t k = 0; k < two.sh.size(); ++k) sh_differ += two.sh[k] != one.sh[k];
    std::printf("frame %d: %llu submissions as two stages, %llu as one; %zu hits, %zu depth texels, %zu SH values differ\n", frame,
                static_cast<unsigned long long>(two_submissions), static_cast<unsigned long long>(one_submission), hits_differ,
                depth_differ, sh_differ);
    EXPECT_EQ(two_submissions, 2u);
    EXPECT_EQ(one_submission, 1u);
    EXPECT_EQ(hits_differ, 0u);
    EXPECT_EQ(depth_differ, 0u);
    EXPECT_EQ(sh_differ, 0u);
    EXPECT_EQ(two.changed, one.changed);
    EXPECT_GT(*std::max_element(one.sh.begin(), one.sh.end()), 0.0f) << "no light came into the probes: the test would prove nothing";
    EXPECT_GT(emitting, 0u) << "no ray met an emitter: the emission's read would prove nothing";
  }
  EXPECT_EQ(ctx->validation_errors(), 0);
}
