#include "gpu/vulkan_ddgi_irradiance.h"

#include <stdexcept>
#include <string>

#include "engine/jobs/parallel_for.h"
#include "gpu/probe_grid_gpu.h"
#include "gpu/shader_path.h"
#include "transgi_shared.h"

namespace transgi::gpu {

VulkanDdgiIrradiance::VulkanDdgiIrradiance(engine::gpu::VulkanContext& ctx) : ctx_(ctx) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("ddgi_irradiance.comp"), 5,
                                                              static_cast<std::uint32_t>(sizeof(DdgiPush)));
}

GpuDdgiIrradiance VulkanDdgiIrradiance::irradiance(const ddgi::DdgiVolume& volume, std::span<const glm::vec3> positions,
                                                   std::span<const glm::vec3> normals,
                                                   std::span<const glm::vec3> view_dirs) {
  if (normals.size() != positions.size() || view_dirs.size() != positions.size())
    throw std::invalid_argument("VulkanDdgiIrradiance: " + std::to_string(positions.size()) + " positions, " +
                                std::to_string(normals.size()) + " normals, " + std::to_string(view_dirs.size()) + " views");
  GpuDdgiIrradiance out;
  const std::size_t n = positions.size();
  if (n == 0) return out;
  const probes::ProbeGrid& grid = volume.grid();
  const auto count = static_cast<std::size_t>(grid.count());
  const int isize = volume.irradiance_map(0).size(), dsize = volume.distance_map(0).size();
  // Straight into the mapped buffers and out of them, in parallel: at 1080p
  // the 2 M points' serial copies took longer than the kernel (docs/gpu-h100.md).
  const std::size_t itexels = static_cast<std::size_t>(isize * isize), dtexels = static_cast<std::size_t>(dsize * dsize);
  const auto pts = engine::gpu::bind_at_least(ctx_, *pipeline_, 0, points_, n * sizeof(DdgiPointGpu)).mapped_as<DdgiPointGpu>(n);
  const auto irr = engine::gpu::bind_at_least(ctx_, *pipeline_, 1, irradiance_, count * itexels * 3 * sizeof(float))
                       .mapped_as<float>(count * itexels * 3);
  const auto dist = engine::gpu::bind_at_least(ctx_, *pipeline_, 2, distance_, count * dtexels * 2 * sizeof(float))
                        .mapped_as<float>(count * dtexels * 2);
  const auto placed = engine::gpu::bind_at_least(ctx_, *pipeline_, 3, placed_, count * sizeof(glm::vec4)).mapped_as<glm::vec4>(count);
  engine::jobs::parallel_for<std::size_t>(0, count, 8, [&](std::size_t q0, std::size_t q1) {
    for (std::size_t q = q0; q < q1; ++q) {
      const auto& im = volume.irradiance_map(static_cast<int>(q));
      const auto& dm = volume.distance_map(static_cast<int>(q));
      for (std::size_t t = 0; t < itexels; ++t)
        for (int c = 0; c < 3; ++c) irr[(q * itexels + t) * 3 + static_cast<std::size_t>(c)] = im.texels[t][c];
      for (std::size_t t = 0; t < dtexels; ++t)
        for (int c = 0; c < 2; ++c) dist[(q * dtexels + t) * 2 + static_cast<std::size_t>(c)] = dm.texels[t][c];
      placed[q] = glm::vec4(volume.placed_grid().position(static_cast<int>(q)), volume.active(static_cast<int>(q)) ? 1.0f : 0.0f);
    }
  });
  engine::jobs::parallel_for<std::size_t>(0, n, 4096, [&](std::size_t b0, std::size_t b1) {
    for (std::size_t i = b0; i < b1; ++i)
      pts[i] = {positions[i].x, positions[i].y, positions[i].z, 0, normals[i].x, normals[i].y, normals[i].z, 0,
                view_dirs[i].x, view_dirs[i].y, view_dirs[i].z, 0};
  });
  engine::gpu::bind_at_least(ctx_, *pipeline_, 4, result_, n * sizeof(glm::vec4));

  const ddgi::DdgiSettings& s = volume.settings();
  DdgiPush push{};
  push.grid = probe_grid_gpu(grid);
  push.normal_bias = volume.biases().x;
  push.view_bias = volume.biases().y;
  push.irradiance_gamma = s.irradiance_gamma;
  push.points = static_cast<int>(n);
  push.irradiance_size = static_cast<uint>(isize), push.distance_size = static_cast<uint>(dsize);
  push.irradiance_interior = static_cast<uint>(volume.irradiance_map(0).interior);
  push.distance_interior = static_cast<uint>(volume.distance_map(0).interior);
  const auto groups = static_cast<std::uint32_t>((n + kDdgiGroupSize - 1) / kDdgiGroupSize);
  out.gpu_ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, groups, 1, 1, &push); });
  const auto r = result_.mapped_as<const glm::vec4>(n);
  out.irradiance.resize(n);
  out.lit.resize(n);
  engine::jobs::parallel_for<std::size_t>(0, n, 4096, [&](std::size_t b0, std::size_t b1) {
    for (std::size_t i = b0; i < b1; ++i) {
      out.irradiance[i] = glm::vec3(r[i]);
      out.lit[i] = r[i].w != 0.0f ? 1 : 0;
    }
  });
  return out;
}

}  // namespace transgi::gpu
