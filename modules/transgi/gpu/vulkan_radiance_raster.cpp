#include "gpu/vulkan_radiance_raster.h"

#include <cstring>
#include <stdexcept>
#include <string>

#include "gpu/shader_path.h"
#include "transgi_shared.h"

namespace transgi::gpu {

VulkanRadianceRaster::VulkanRadianceRaster(engine::gpu::VulkanContext& ctx, probes::MapLayout layout)
    : ctx_(ctx), layout_(layout) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("radiance_raster.comp"), 7,
                                                              static_cast<std::uint32_t>(sizeof(RasterPush)));
}

engine::gpu::GpuBuffer& VulkanRadianceRaster::sized(engine::gpu::GpuBuffer& b, std::uint32_t binding, std::size_t bytes) {
  if (b.handle() == VK_NULL_HANDLE || b.size() < bytes) {
    b = engine::gpu::GpuBuffer(ctx_, bytes);
    pipeline_->bind(binding, b);
  }
  return b;
}

probes::SharingStats VulkanRadianceRaster::rasterize(const probes::ProbeGrid& grid,
                                                     const std::vector<std::vector<probes::ShadedPoint>>& points,
                                                     const std::vector<const probes::DepthMap*>& own_depth,
                                                     const probes::SharingSettings& s,
                                                     std::vector<probes::FrameSamples>& out,
                                                     std::span<const std::uint8_t> targets, double* gpu_ms) {
  const auto count = static_cast<std::size_t>(grid.count());
  const auto texels = static_cast<std::size_t>(layout_.texel_count());
  if (points.size() != count || (!own_depth.empty() && own_depth.size() != count) ||
      (!targets.empty() && targets.size() != count) || (!grid.offsets.empty() && grid.offsets.size() != count))
    throw std::invalid_argument("VulkanRadianceRaster: " + std::to_string(count) + " probes but points for " +
                                std::to_string(points.size()) + ", depth for " + std::to_string(own_depth.size()) +
                                ", " + std::to_string(targets.size()) + " target flags");
  out.resize(count);

  std::vector<ShadedPointGpu> flat;
  std::vector<std::uint32_t> begin(count + 1, 0);
  for (std::size_t q = 0; q < count; ++q) {
    begin[q] = static_cast<std::uint32_t>(flat.size());
    for (const auto& pt : points[q])
      flat.push_back({pt.position.x, pt.position.y, pt.position.z, pt.distance, pt.radiance.x, pt.radiance.y,
                      pt.radiance.z, 0, pt.direction.x, pt.direction.y, pt.direction.z, 0, pt.normal.x, pt.normal.y,
                      pt.normal.z, 0});
  }
  begin[count] = static_cast<std::uint32_t>(flat.size());
  // A depth guard needs every probe's map; a probe without one (null) reads
  // as "never hit" (NaN), which the guard lets through, as the CPU does.
  const bool has_depth = !own_depth.empty();
  std::vector<probes::DepthMap::Texel> depth(has_depth ? count * texels : 1);
  std::vector<ProbeGpu> info(count);
  std::vector<std::uint32_t> target_flags(count, 1);
  for (std::size_t q = 0; q < count; ++q) {
    const probes::DepthMap* d = has_depth ? own_depth[q] : nullptr;
    if (d && d->texels.size() == texels) std::memcpy(&depth[q * texels], d->texels.data(), texels * sizeof(depth[0]));
    const glm::vec3 off = grid.offsets.empty() ? glm::vec3(0.0f) : grid.offsets[q];
    info[q] = {off.x, off.y, off.z, d ? d->unit : 1.0f, 0, 0, 0, 0};
    if (!targets.empty()) target_flags[q] = targets[q] ? 1u : 0u;
  }
  sized(points_, 0, flat.size() * sizeof(ShadedPointGpu)).upload(std::span<const ShadedPointGpu>(flat));
  sized(ranges_, 1, begin.size() * sizeof(std::uint32_t)).upload(std::span<const std::uint32_t>(begin));
  sized(depth_, 2, depth.size() * sizeof(depth[0])).upload(std::span<const probes::DepthMap::Texel>(depth));
  sized(probes_, 3, info.size() * sizeof(ProbeGpu)).upload(std::span<const ProbeGpu>(info));
  sized(targets_, 4, target_flags.size() * sizeof(std::uint32_t)).upload(std::span<const std::uint32_t>(target_flags));
  sized(samples_, 5, count * texels * 4 * sizeof(float));
  const std::uint32_t zero[2] = {0, 0};
  sized(stats_, 6, sizeof(zero)).upload(std::span<const std::uint32_t>(zero));

  const glm::vec3 sp = grid.spacing();
  RasterPush push{};
  push.min_x = grid.min.x, push.min_y = grid.min.y, push.min_z = grid.min.z;
  push.relative_tolerance = s.relative_tolerance;
  push.spacing_x = sp.x, push.spacing_y = sp.y, push.spacing_z = sp.z;
  push.absolute_tolerance = s.absolute_tolerance;
  push.dims_x = grid.dims.x, push.dims_y = grid.dims.y, push.dims_z = grid.dims.z;
  push.probes = static_cast<int>(count);
  push.scroll_x = grid.scroll.x, push.scroll_y = grid.scroll.y, push.scroll_z = grid.scroll.z;
  const bool guard = s.mode == probes::SharingMode::DepthGuard;
  push.flags = (guard ? kRasterDepthGuard : 0u) | (s.same_side ? kRasterSameSide : 0u) | (has_depth ? kRasterHasDepth : 0u) |
               (grid.offsets.empty() ? 0u : kRasterHasOffsets);
  push.map_width = static_cast<uint>(layout_.width);
  push.map_height = static_cast<uint>(layout_.height);
  push.texels = static_cast<uint>(texels);
  const double ms = ctx_.submit_and_wait(
      [&](VkCommandBuffer cmd) { pipeline_->record_dispatch(cmd, static_cast<std::uint32_t>(count), 1, 1, &push); });
  if (gpu_ms) *gpu_ms = ms;

  std::vector<float> samples(count * texels * 4);
  samples_.download(std::span<float>(samples));
  for (std::size_t q = 0; q < count; ++q) {
    if (!target_flags[q]) continue;
    auto& fs = out[q];
    fs.reset(static_cast<int>(texels));
    for (std::size_t t = 0; t < texels; ++t) {
      const float* v = &samples[(q * texels + t) * 4];
      fs.sum[t] = glm::vec3(v[0], v[1], v[2]);
      fs.count[t] = v[3];
    }
  }
  std::uint32_t stats[2];
  stats_.download(std::span<std::uint32_t>(stats));
  return {stats[0], stats[1]};
}

}  // namespace transgi::gpu
