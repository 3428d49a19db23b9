// shaders/radiance_raster.comp against probes::rasterize_shared_reference
// (its CPU stage): same frame samples, same guard decisions, on a scrolled
// grid with relocated probes, escaped rays and a budget that skips probes.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/math/rng.h"
#include "gpu/vulkan_probe_kernels.h"
#include "gpu/vulkan_radiance_raster.h"
#include "probes/cpu_probe_kernels.h"
#include "gpu_fixture.h"
#include "probe_kernels_fixture.h"

using namespace transgi;

namespace {

struct Frame {
  probes::ProbeGrid grid;
  probes::MapLayout layout{40, 20};
  std::vector<std::vector<probes::ShadedPoint>> points;
  std::vector<probes::DepthMap> depth;
  std::vector<const probes::DepthMap*> depth_ptrs;
  std::vector<std::uint8_t> targets;
};

Frame random_frame(std::uint64_t seed) {
  Frame f;
  f.grid = probes::ProbeGrid{glm::vec3(0.0f), glm::vec3(3.0f, 2.0f, 2.0f), glm::ivec3(4, 3, 3)};
  f.grid.scroll = glm::ivec3(1, 0, 2);
  engine::math::Pcg32 rng(seed, 13);
  auto r3 = [&] { return glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) - 0.5f; };
  const int count = f.grid.count();
  const float unit = f.grid.min_spacing();
  f.grid.offsets.resize(static_cast<std::size_t>(count));
  for (auto& o : f.grid.offsets) o = 0.3f * unit * r3();
  f.points.resize(static_cast<std::size_t>(count));
  f.depth.resize(static_cast<std::size_t>(count));
  f.targets.resize(static_cast<std::size_t>(count));
  for (int q = 0; q < count; ++q) {
    const glm::vec3 origin = f.grid.position(q);
    for (int i = 0; i < 80; ++i) {
      probes::ShadedPoint pt;
      pt.direction = glm::normalize(r3() + glm::vec3(1e-3f));
      const bool escaped = rng.next_float() < 0.1f;
      pt.distance = escaped ? INFINITY : unit * (0.1f + 2.4f * rng.next_float());
      pt.position = escaped ? glm::vec3(0.0f) : origin + pt.direction * pt.distance;
      pt.radiance = glm::vec3(rng.next_float(), rng.next_float(), rng.next_float()) * 3.0f;
      // Mostly facing the shooting probe; a fifth turned away (thin walls seen from the other side).
      pt.normal = glm::normalize(-pt.direction + 0.8f * r3());
      if (rng.next_float() < 0.2f) pt.normal = -pt.normal;
      f.points[static_cast<std::size_t>(q)].push_back(pt);
    }
    auto& d = f.depth[static_cast<std::size_t>(q)];
    d.reset(f.layout.texel_count(), unit);
    for (int t = 0; t < f.layout.texel_count(); ++t)
      d.set(static_cast<std::size_t>(t), rng.next_float() < 0.1f ? NAN : unit * (0.3f + 1.7f * rng.next_float()), 0.0f);
    f.targets[static_cast<std::size_t>(q)] = rng.next_float() < 0.8f ? 1 : 0;
  }
  for (auto& d : f.depth) f.depth_ptrs.push_back(&d);
  return f;
}

// The probes a frame updates (its targets), in order.
std::vector<int> updated_probes(const Frame& f) {
  std::vector<int> batch;
  for (int q = 0; q < f.grid.count(); ++q)
    if (f.targets[static_cast<std::size_t>(q)]) batch.push_back(q);
  return batch;
}

// The device's SH against the CPU's: each coefficient within 1e-3 of the largest.
void expect_sh_near(const std::vector<float>& cpu_sh, const std::vector<float>& gpu_sh, int frame) {
  float largest = 0.0f, worst = 0.0f;
  for (const float v : cpu_sh) largest = std::max(largest, std::abs(v));
  ASSERT_GT(largest, 0.0f);
  for (std::size_t k = 0; k < cpu_sh.size(); ++k) worst = std::max(worst, std::abs(gpu_sh[k] - cpu_sh[k]));
  std::printf("frame %d: largest SH coefficient %.4g, largest difference %.3g\n", frame, largest, worst);
  EXPECT_LE(worst, 1e-3f * largest) << "frame " << frame;
}

}  // namespace

// Rounding may put a point the other side of a texel border or of the
// depth guard's bound (see probe_interpolation_test.cpp): at most 0.1 % of
// the texels may hold a different count (measured 0); the rest match to
// 1e-5 relative, the accepted and rejected totals to 0.1 %.
TEST(VulkanRadianceRaster, EqualsTheCpuStageWithGuardsAndABudget) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  const Frame f = random_frame(23);
  const probes::SharingSettings settings;
  std::vector<probes::FrameSamples> want, got;
  const auto want_stats =
      probes::rasterize_shared_reference(f.grid, f.layout, f.points, f.depth_ptrs, settings, want, f.targets);
  gpu::VulkanRadianceRaster raster(*ctx, f.layout);
  const auto got_stats = raster.rasterize(f.grid, f.points, f.depth_ptrs, settings, got, f.targets);
  ASSERT_EQ(got.size(), want.size());
  std::size_t texels = 0, differ = 0, bad = 0, filled = 0;
  for (std::size_t q = 0; q < want.size(); ++q) {
    if (!f.targets[q]) {
      EXPECT_TRUE(got[q].count.empty()) << "probe " << q << " was outside the budget and must stay untouched";
      continue;
    }
    for (std::size_t t = 0; t < want[q].count.size(); ++t) {
      ++texels;
      filled += want[q].count[t] > 0;
      if (want[q].count[t] != got[q].count[t]) {
        ++differ;
        continue;
      }
      for (int c = 0; c < 3; ++c)
        if (!(std::abs(want[q].sum[t][c] - got[q].sum[t][c]) <= 1e-5f * (1.0f + std::abs(want[q].sum[t][c]))) && bad++ < 5)
          ADD_FAILURE() << "probe " << q << " texel " << t << " channel " << c << ": expected " << want[q].sum[t][c]
                        << ", got " << got[q].sum[t][c];
    }
  }
  std::printf("raster: %zu texels (%zu with samples), %zu counts differ; accepted %zu / %zu, rejected %zu / %zu (cpu / gpu)\n",
              texels, filled, differ, want_stats.accepted, got_stats.accepted, want_stats.rejected_by_guard,
              got_stats.rejected_by_guard);
  EXPECT_EQ(bad, 0u);
  EXPECT_LE(differ, texels / 1000);
  EXPECT_NEAR(static_cast<double>(got_stats.accepted), static_cast<double>(want_stats.accepted), 1e-3 * want_stats.accepted);
  EXPECT_NEAR(static_cast<double>(got_stats.rejected_by_guard), static_cast<double>(want_stats.rejected_by_guard),
              1e-3 * want_stats.rejected_by_guard);
  EXPECT_GT(want_stats.rejected_by_guard, 100u) << "the frame should exercise the guards";
  EXPECT_EQ(ctx->validation_errors(), 0);
}

// Paper-faithful sharing (no guard) and no depth maps: every point that is
// not at a probe lands in some texel, so the counts add up to a known total.
TEST(VulkanRadianceRaster, WithoutGuardsEveryPointIsCountedOncePerNeighbour) {
  GPU_TEST_CONTEXT_OR_SKIP(ctx);
  Frame f = random_frame(5);
  std::fill(f.targets.begin(), f.targets.end(), std::uint8_t{1});
  probes::SharingSettings settings;
  settings.mode = probes::SharingMode::PaperFaithful;
  std::vector<probes::FrameSamples> got;
  gpu::VulkanRadianceRaster raster(*ctx, f.layout);
  const auto stats = raster.rasterize(f.grid, f.points, {}, settings, got);
  std::size_t expected = 0;
  for (int p = 0; p < f.grid.count(); ++p)
    f.grid.for_each_neighbour(p, [&](int q) {
      for (const auto& pt : f.points[static_cast<std::size_t>(q)]) expected += std::isfinite(pt.distance) || q == p;
    });
  double total = 0;
  for (const auto& fs : got)
    for (float c : fs.count) total += c;
  EXPECT_EQ(stats.accepted, expected);
  EXPECT_EQ(stats.rejected_by_guard, 0u);
  EXPECT_EQ(total, static_cast<double>(expected));
}

// The probe field's last stages as the Vulkan backend runs them: the raster,
// the accumulation and the SH projection in one submission, the samples and
// the filled maps kept on the device (only the maps' states, the SH and the
// guard's counts come back), against the CPU backend over two frames.
// Bounds: the raster's (above) and the accumulation's (the change test sums
// in float on the device, in double on the CPU): each SH coefficient within
// 1e-3 of the largest, every change flag equal.
TEST(VulkanProbeKernels, ShareAccumulateProjectIsOneSubmissionAndEqualsTheCpuBackend) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  OWN_PROBE_KERNELS_OR_SKIP(own);
  const std::shared_ptr<engine::gpu::VulkanContext>& ctx = own.ctx;
  const std::shared_ptr<gpu::VulkanProbeKernels>& gpu_kernels = own.kernels;
  probes::CpuProbeKernels cpu_kernels;
  const Frame f = random_frame(29);
  const probes::MapProjector projector(f.layout);
  const probes::SharingSettings sharing;
  const probes::AccumulationSettings accumulation;
  const std::vector<int> batch = updated_probes(f);
  const auto fresh_states = [&] {
    std::vector<probes::ProbeMapState> s(batch.size());
    for (auto& m : s) m.reset(f.layout.texel_count(), f.grid.min_spacing());
    return s;
  };
  std::vector<probes::ProbeMapState> cpu_states = fresh_states(), gpu_states = fresh_states();
  const auto pointers = [](std::vector<probes::ProbeMapState>& s) {
    std::vector<probes::ProbeMapState*> p;
    for (auto& m : s) p.push_back(&m);
    return p;
  };
  const std::vector<probes::ProbeMapState*> cpu_ptrs = pointers(cpu_states), gpu_ptrs = pointers(gpu_states);
  for (int frame = 0; frame < 2; ++frame) {
    std::vector<std::uint8_t> cpu_changed(batch.size()), gpu_changed(batch.size());
    std::vector<float> cpu_sh(batch.size() * 75), gpu_sh(batch.size() * 75);
    probes::ShareAccumulateTimes times;
    const auto cpu_stats = cpu_kernels.share_accumulate_project(f.grid, projector, f.points, f.depth_ptrs, sharing, batch, cpu_ptrs, nullptr,
                                                                accumulation, cpu_changed, cpu_sh, times);
    const engine::gpu::GpuTraffic before = ctx->traffic();
    const auto gpu_stats = gpu_kernels->share_accumulate_project(f.grid, projector, f.points, f.depth_ptrs, sharing, batch, gpu_ptrs, nullptr,
                                                                 accumulation, gpu_changed, gpu_sh, times);
    const engine::gpu::GpuTraffic t = ctx->traffic() - before;
    const std::size_t texels = static_cast<std::size_t>(f.layout.texel_count());
    // The maps' states (binary16 history, sampled flags, 32-byte state), the
    // SH and the guard's two counts; not the samples (16 bytes a texel of
    // every grid probe) nor the filled maps (12 bytes a texel).
    const std::uint64_t states_back = batch.size() * (texels * (8 + 4) + 32), sh_back = batch.size() * 75 * 4;
    std::printf("frame %d: %llu submission(s), %llu bytes back (states %llu, SH %llu)\n", frame,
                static_cast<unsigned long long>(t.submissions), static_cast<unsigned long long>(t.device_to_host_bytes),
                static_cast<unsigned long long>(states_back), static_cast<unsigned long long>(sh_back));
    EXPECT_EQ(t.submissions, 1u);
    EXPECT_LE(t.device_to_host_bytes, states_back + sh_back + 8);
    EXPECT_NEAR(static_cast<double>(gpu_stats.accepted), static_cast<double>(cpu_stats.accepted), 1e-3 * cpu_stats.accepted);
    EXPECT_NEAR(static_cast<double>(gpu_stats.rejected_by_guard), static_cast<double>(cpu_stats.rejected_by_guard),
                1e-3 * cpu_stats.rejected_by_guard + 1);
    EXPECT_EQ(gpu_changed, cpu_changed) << "frame " << frame;
    expect_sh_near(cpu_sh, gpu_sh, frame);
  }
}

// The maps kept on the device between updates (VulkanMapStore): over five
// updates, one probe reset on the host between the second and third, and
// the maps read back before the fifth (so that they go up again, through
// the staging copy), every update's SH and change flags equal the CPU
// backend's as above; no map comes back unless read back, and none goes up
// once the device holds it; the maps read back equal the CPU's to binary16
// rounding.
namespace {
// With stage_device_only, the store's buffers are written and read through
// staging copies, as on a discrete GPU.
void maps_stay_on_the_device(bool stage_device_only) {
  engine::gpu::GpuOptions options;
  options.stage_device_only = stage_device_only;
  OWN_PROBE_KERNELS_OR_SKIP(own, options);
  const std::shared_ptr<engine::gpu::VulkanContext>& ctx = own.ctx;
  const std::shared_ptr<gpu::VulkanProbeKernels>& gpu_kernels = own.kernels;
  probes::CpuProbeKernels cpu_kernels;
  Frame f = random_frame(31);
  for (probes::DepthMap& d : f.depth) d.stamp_version();  // as update_own_depth leaves them
  const probes::MapProjector projector(f.layout);
  const probes::SharingSettings sharing;
  const probes::AccumulationSettings accumulation;
  const std::vector<int> batch = updated_probes(f);
  const std::size_t texels = static_cast<std::size_t>(f.layout.texel_count());
  // One state a probe of the grid, as a field keeps them; the batch points into them.
  const auto fresh_states = [&] {
    std::vector<probes::ProbeMapState> s(static_cast<std::size_t>(f.grid.count()));
    for (auto& m : s) m.reset(f.layout.texel_count(), f.grid.min_spacing());
    return s;
  };
  std::vector<probes::ProbeMapState> cpu_states = fresh_states(), gpu_states = fresh_states(), plain_states = fresh_states();
  const auto pointers = [&](std::vector<probes::ProbeMapState>& s) {
    std::vector<probes::ProbeMapState*> p;
    for (const int q : batch) p.push_back(&s[static_cast<std::size_t>(q)]);
    return p;
  };
  const std::vector<probes::ProbeMapState*> cpu_ptrs = pointers(cpu_states), gpu_ptrs = pointers(gpu_states),
                                            plain_ptrs = pointers(plain_states);
  std::unique_ptr<probes::ProbeMapStore> store = gpu_kernels->make_map_store(f.layout, f.grid.count());
  ASSERT_TRUE(store);
  const std::uint64_t maps_bytes = batch.size() * texels * (8 + 4), depth_bytes = f.depth.size() * texels * 4;
  for (int frame = 0; frame < 5; ++frame) {
    if (frame == 3) {  // a probe's own depth moved in: its neighbours' guard rejects what lies past it
      probes::DepthMap& d = f.depth[static_cast<std::size_t>(batch[1])];
      for (std::size_t t = 0; t < texels; ++t) d.set(t, 0.2f * f.grid.min_spacing(), 0.0f);
      d.stamp_version();
    }
    if (frame == 2) {  // a probe restarted on the host: its fresh (blank) maps replace the device's
      cpu_states[static_cast<std::size_t>(batch[0])].reset(f.layout.texel_count(), f.grid.min_spacing());
      gpu_states[static_cast<std::size_t>(batch[0])].reset(f.layout.texel_count(), f.grid.min_spacing());
      plain_states[static_cast<std::size_t>(batch[0])].reset(f.layout.texel_count(), f.grid.min_spacing());
    }
    if (frame == 4) {
      store->read_back(gpu_states);
      for (const int q : batch) {
        const probes::ProbeMapState& g = gpu_states[static_cast<std::size_t>(q)];
        const probes::ProbeMapState& c = cpu_states[static_cast<std::size_t>(q)];
        ASSERT_EQ(g.device_stamp, 0u) << "probe " << q;
        float largest = 0.0f, worst = 0.0f;
        for (std::size_t t = 0; t < texels; ++t) {
          largest = std::max(largest, c.radiance_at(t).r);
          worst = std::max(worst, std::abs(g.radiance_at(t).r - c.radiance_at(t).r));
          ASSERT_EQ(g.sampled[t], c.sampled[t]) << "probe " << q << " texel " << t;
        }
        EXPECT_LE(worst, 2e-3f * largest) << "probe " << q;
      }
    }
    std::vector<std::uint8_t> cpu_changed(batch.size()), gpu_changed(batch.size()), plain_changed(batch.size());
    std::vector<float> cpu_sh(batch.size() * 75), gpu_sh(batch.size() * 75), plain_sh(batch.size() * 75);
    probes::ShareAccumulateTimes times;
    const probes::SharingStats cpu_stats = cpu_kernels.share_accumulate_project(
        f.grid, projector, f.points, f.depth_ptrs, sharing, batch, cpu_ptrs, nullptr, accumulation, cpu_changed, cpu_sh, times);
    engine::gpu::GpuTraffic before = ctx->traffic();
    gpu_kernels->share_accumulate_project(f.grid, projector, f.points, f.depth_ptrs, sharing, batch, plain_ptrs, nullptr,
                                          accumulation, plain_changed, plain_sh, times);
    const engine::gpu::GpuTraffic plain = ctx->traffic() - before;
    before = ctx->traffic();
    const probes::SharingStats gpu_stats = gpu_kernels->share_accumulate_project(
        f.grid, projector, f.points, f.depth_ptrs, sharing, batch, gpu_ptrs, store.get(), accumulation, gpu_changed, gpu_sh, times);
    const engine::gpu::GpuTraffic t = ctx->traffic() - before;
    std::printf("frame %d: maps on the device: %llu bytes up, %llu back; sent each update: %llu up, %llu back\n", frame,
                static_cast<unsigned long long>(t.host_to_device_bytes), static_cast<unsigned long long>(t.device_to_host_bytes),
                static_cast<unsigned long long>(plain.host_to_device_bytes), static_cast<unsigned long long>(plain.device_to_host_bytes));
    EXPECT_EQ(t.submissions, 1u) << "frame " << frame;
    // Back: the states' 32-byte scalars, the SH and the guard's two counts.
    EXPECT_LE(t.device_to_host_bytes, batch.size() * (32 + 75 * 4) + 8) << "frame " << frame;
    EXPECT_GE(plain.device_to_host_bytes, t.device_to_host_bytes + maps_bytes) << "frame " << frame;
    // Up: the maps only where the device does not hold them (after the
    // read-back), a blank map never; the depth maps on the first update,
    // then only the one whose version changed.
    const std::uint64_t maps_up = frame == 4 ? maps_bytes : 0,
                        depth_up = frame == 0 ? depth_bytes : frame == 3 ? texels * 4 : 0;
    // (The first plain update also sent the kernels' constant tables, made for it.)
    if (frame == 0)
      EXPECT_LE(t.host_to_device_bytes + maps_bytes + depth_bytes, plain.host_to_device_bytes + maps_up + depth_up);
    else
      EXPECT_EQ(t.host_to_device_bytes + maps_bytes + depth_bytes, plain.host_to_device_bytes + maps_up + depth_up) << "frame " << frame;
    std::printf("frame %d: %zu samples accepted, %zu rejected by the depth guard (the CPU: %zu, %zu)\n", frame, gpu_stats.accepted,
                gpu_stats.rejected_by_guard, cpu_stats.accepted, cpu_stats.rejected_by_guard);
    EXPECT_NEAR(static_cast<double>(gpu_stats.rejected_by_guard), static_cast<double>(cpu_stats.rejected_by_guard),
                1e-3 * cpu_stats.rejected_by_guard + 1) << "frame " << frame;
    EXPECT_EQ(gpu_changed, cpu_changed) << "frame " << frame;
    expect_sh_near(cpu_sh, gpu_sh, frame);
  }
  // A state the device holds is refused by the CPU backend until read back.
  std::vector<std::uint8_t> changed(batch.size());
  std::vector<float> sh(batch.size() * 75);
  probes::ShareAccumulateTimes times;
  EXPECT_THROW(cpu_kernels.share_accumulate_project(f.grid, projector, f.points, f.depth_ptrs, sharing, batch, gpu_ptrs, nullptr,
                                                    accumulation, changed, sh, times),
               std::logic_error);
  EXPECT_EQ(ctx->validation_errors(), 0);
}
}  // namespace

TEST(VulkanMapStore, TheMapsStayOnTheDeviceAndEqualTheCpuBackend) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  maps_stay_on_the_device(false);
}

TEST(VulkanMapStore, TheSameThroughStagingCopiesAsOnADiscreteGpu) {
  GPU_TEST_CONTEXT_OR_SKIP(unused);
  maps_stay_on_the_device(true);
}
