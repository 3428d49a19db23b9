#include "gpu/vulkan_ddgi_irradiance.h"

#include <stdexcept>
#include <string>

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
  std::vector<float> irr(count * static_cast<std::size_t>(isize * isize) * 3), dist(count * static_cast<std::size_t>(dsize * dsize) * 2);
  std::vector<glm::vec4> placed(count);
  for (std::size_t q = 0; q < count; ++q) {
    const auto& im = volume.irradiance_map(static_cast<int>(q));
    const auto& dm = volume.distance_map(static_cast<int>(q));
    for (std::size_t t = 0; t < im.texels.size(); ++t)
      for (int c = 0; c < 3; ++c) irr[(q * im.texels.size() + t) * 3 + static_cast<std::size_t>(c)] = im.texels[t][c];
    for (std::size_t t = 0; t < dm.texels.size(); ++t)
      for (int c = 0; c < 2; ++c) dist[(q * dm.texels.size() + t) * 2 + static_cast<std::size_t>(c)] = dm.texels[t][c];
    placed[q] = glm::vec4(volume.placed_grid().position(static_cast<int>(q)), volume.active(static_cast<int>(q)) ? 1.0f : 0.0f);
  }
  std::vector<DdgiPointGpu> pts(n);
  for (std::size_t i = 0; i < n; ++i)
    pts[i] = {positions[i].x, positions[i].y, positions[i].z, 0, normals[i].x, normals[i].y, normals[i].z, 0,
              view_dirs[i].x, view_dirs[i].y, view_dirs[i].z, 0};
  engine::gpu::bind_at_least(ctx_, *pipeline_, 0, points_, n * sizeof(DdgiPointGpu)).upload(std::span<const DdgiPointGpu>(pts));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 1, irradiance_, irr.size() * sizeof(float)).upload(std::span<const float>(irr));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 2, distance_, dist.size() * sizeof(float)).upload(std::span<const float>(dist));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 3, placed_, placed.size() * sizeof(glm::vec4)).upload(std::span<const glm::vec4>(placed));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 4, result_, n * sizeof(glm::vec4));

  const ddgi::DdgiSettings& s = volume.settings();
  DdgiPush push{};
  push.grid = probe_grid_gpu(grid);
  push.normal_bias = s.normal_bias;
  push.view_bias = s.view_bias;
  push.irradiance_gamma = s.irradiance_gamma;
  push.points = static_cast<int>(n);
  push.irradiance_size = static_cast<uint>(isize), push.distance_size = static_cast<uint>(dsize);
  push.irradiance_interior = static_cast<uint>(volume.irradiance_map(0).interior);
  push.distance_interior = static_cast<uint>(volume.distance_map(0).interior);
  const auto groups = static_cast<std::uint32_t>((n + kDdgiGroupSize - 1) / kDdgiGroupSize);
  out.gpu_ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, groups, 1, 1, &push); });
  std::vector<glm::vec4> r(n);
  result_.download(std::span<glm::vec4>(r));
  out.irradiance.resize(n);
  out.lit.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.irradiance[i] = glm::vec3(r[i]);
    out.lit[i] = r[i].w != 0.0f ? 1 : 0;
  }
  return out;
}

}  // namespace transgi::gpu
