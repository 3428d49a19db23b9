#include "gpu/vulkan_probe_interpolator.h"

#include <cstring>
#include <stdexcept>
#include <string>

#include "gpu/probe_grid_gpu.h"
#include "gpu/shader_path.h"
#include "transgi_shared.h"

namespace transgi::gpu {

VulkanProbeInterpolator::VulkanProbeInterpolator(engine::gpu::VulkanContext& ctx, probes::MapLayout layout)
    : ctx_(ctx), layout_(layout) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("probe_interpolation.comp"), 6,
                                                              static_cast<std::uint32_t>(sizeof(InterpolatePush)));
}

GpuInterpolation VulkanProbeInterpolator::interpolate(const probes::ProbeGrid& grid,
                                                      const std::vector<probes::ProbeMapState>& states,
                                                      std::span<const float> probe_sh, std::span<const std::uint8_t> usable,
                                                      const probes::InterpolationSettings& settings,
                                                      std::span<const glm::vec3> positions,
                                                      std::span<const glm::vec3> normals, const glm::vec3* viewer) {
  const auto count = static_cast<std::size_t>(grid.count());
  const auto texels = static_cast<std::size_t>(layout_.texel_count());
  if (states.size() != count || probe_sh.size() != count * kTransferOutputs || (!usable.empty() && usable.size() != count) ||
      normals.size() != positions.size() || (!grid.offsets.empty() && grid.offsets.size() != count))
    throw std::invalid_argument("VulkanProbeInterpolator: " + std::to_string(count) + " probes but " +
                                std::to_string(states.size()) + " states, " + std::to_string(probe_sh.size()) +
                                " SH values, " + std::to_string(usable.size()) + " usable flags; " +
                                std::to_string(positions.size()) + " positions, " + std::to_string(normals.size()) + " normals");
  GpuInterpolation out;
  const std::size_t n = positions.size();
  if (n == 0) return out;

  std::vector<float> points(n * 6);
  for (std::size_t i = 0; i < n; ++i) {
    std::memcpy(&points[i * 6], &positions[i].x, 3 * sizeof(float));
    std::memcpy(&points[i * 6 + 3], &normals[i].x, 3 * sizeof(float));
  }
  std::vector<std::uint32_t> depth(count * texels);
  std::vector<ProbeGpu> probe_info(count);
  write_probe_field(grid, states, usable, texels, 0, 0, depth, probe_info);
  engine::gpu::bind_at_least(ctx_, *pipeline_, 0, points_, points.size() * sizeof(float)).upload(std::span<const float>(points));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 1, depth_, depth.size() * sizeof(depth[0])).upload(std::span<const std::uint32_t>(depth));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 2, probes_, probe_info.size() * sizeof(ProbeGpu)).upload(std::span<const ProbeGpu>(probe_info));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 3, probe_sh_, probe_sh.size() * sizeof(float)).upload(probe_sh);
  engine::gpu::bind_at_least(ctx_, *pipeline_, 4, results_, n * sizeof(InterpolationGpu));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 5, point_sh_, n * kTransferOutputs * sizeof(float));

  InterpolatePush push = interpolate_push(grid, layout_, settings, viewer);
  push.points = static_cast<int>(n);
  const auto groups = static_cast<std::uint32_t>((n + kInterpolateGroupSize - 1) / kInterpolateGroupSize);
  out.gpu_ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, groups, 1, 1, &push); });

  std::vector<InterpolationGpu> raw(n);
  results_.download(std::span<InterpolationGpu>(raw));
  out.results.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t c = 0; c < 8; ++c) {
      out.results[i].probes[c] = raw[i].probes[c];
      out.results[i].weights[c] = raw[i].weights[c];
    }
    out.results[i].pruned = static_cast<int>(raw[i].pruned);
    out.results[i].fallback = raw[i].fallback != 0;
  }
  out.light_sh.resize(n * kTransferOutputs);
  point_sh_.download(std::span<float>(out.light_sh));
  return out;
}

}  // namespace transgi::gpu
