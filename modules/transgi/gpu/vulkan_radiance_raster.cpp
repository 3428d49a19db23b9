#include "gpu/vulkan_radiance_raster.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "engine/jobs/parallel_for.h"
#include "gpu/probe_grid_gpu.h"
#include "gpu/shader_path.h"
#include "probe_shading_shared.h"
#include "transgi_shared.h"

namespace transgi::gpu {

VulkanRadianceRaster::VulkanRadianceRaster(engine::gpu::VulkanContext& ctx, probes::MapLayout layout)
    : ctx_(ctx), layout_(layout) {
  pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx, compile_module_shader("radiance_raster.comp"), 7,
                                                              static_cast<std::uint32_t>(sizeof(RasterPush)));
}

namespace {
// Whether every probe's points are its rays' in `rays` (all of them, or none
// where the host dropped them) and no other probe has any; if so, where each
// tracing probe's points begin in the raster's list (kProbePointsSkip: none).
bool points_from_rays(const std::vector<std::vector<probes::ShadedPoint>>& points,
                      const VulkanRadianceRaster::DevicePoints& rays, const std::vector<std::uint32_t>& begin,
                      std::vector<std::uint32_t>& first) {
  if (!rays.hits || !rays.directions || rays.rays_per_probe == 0) return false;
  const std::size_t m = rays.rays_per_probe;
  if (rays.hits->size() < rays.tracing.size() * m * sizeof(ProbeRayHitGpu) || rays.directions->size() < m * sizeof(glm::vec4))
    return false;
  first.assign(rays.tracing.size(), kProbePointsSkip);
  std::size_t taken = 0;
  for (std::size_t j = 0; j < rays.tracing.size(); ++j) {
    const int q = rays.tracing[j];
    if (q < 0 || static_cast<std::size_t>(q) >= points.size()) return false;
    const std::size_t n = points[static_cast<std::size_t>(q)].size();
    if (n == 0) continue;
    if (n != m) return false;
    first[j] = begin[static_cast<std::size_t>(q)];
    taken += m;
  }
  return taken == begin.back();  // no probe has other points (nor one traced twice)
}
}  // namespace

bool VulkanRadianceRaster::bind_device_points(const std::vector<std::vector<probes::ShadedPoint>>& points,
                                              const DevicePoints& rays, const std::vector<std::uint32_t>& begin) {
  std::vector<std::uint32_t> first;
  points_on_device_ = points_from_rays(points, rays, begin, first);
  if (!points_on_device_) return false;
  bind_rays_as_points(rays, begin, first);
  return true;
}

void VulkanRadianceRaster::bind_rays_as_points(const DevicePoints& rays, const std::vector<std::uint32_t>& begin,
                                               const std::vector<std::uint32_t>& first) {
  points_on_device_ = true;
  if (!points_pipeline_)
    points_pipeline_ = std::make_unique<engine::gpu::ComputePipeline>(ctx_, compile_module_shader("probe_points.comp"), 4,
                                                                      static_cast<std::uint32_t>(sizeof(point_push_)));
  const std::size_t bytes = std::max<std::size_t>(1, begin.back()) * sizeof(ShadedPointGpu);
  if (device_points_.handle() == VK_NULL_HANDLE || device_points_.size() < bytes)
    device_points_ = engine::gpu::GpuBuffer(ctx_, bytes, engine::gpu::GpuBuffer::Placement::DeviceOnly);
  engine::gpu::bind_at_least(ctx_, *points_pipeline_, 2, first_point_, first.size() * sizeof(std::uint32_t))
      .upload(std::span<const std::uint32_t>(first));
  points_pipeline_->bind(0, *rays.hits);
  points_pipeline_->bind(1, *rays.directions);
  points_pipeline_->bind(2, first_point_);
  points_pipeline_->bind(3, device_points_);
  pipeline_->bind(0, device_points_);
  point_push_[0] = static_cast<std::uint32_t>(first.size()) * rays.rays_per_probe;
  point_push_[1] = rays.rays_per_probe;
  point_groups_ = (point_push_[0] + kProbeShadingGroupSize - 1) / kProbeShadingGroupSize;
}

void VulkanRadianceRaster::bind_depth(const std::vector<const probes::DepthMap*>& own_depth, std::size_t host_texels) {
  if (store_) {
    store_->stage_depth(own_depth);
    pipeline_->bind(2, store_->depth());
    return;
  }
  engine::gpu::bind_at_least(ctx_, *pipeline_, 2, depth_, host_texels * sizeof(probes::DepthMap::Texel));
  pipeline_->bind(2, depth_);  // a store's may have been bound since
}

void VulkanRadianceRaster::prepare(const probes::ProbeGrid& grid, const std::vector<std::vector<probes::ShadedPoint>>& points,
                                   const std::vector<const probes::DepthMap*>& own_depth, const probes::SharingSettings& s,
                                   std::span<const std::uint8_t> targets, VulkanMapStore* store,
                                   const DevicePoints* device_points) {
  std::vector<std::uint32_t> begin(points.size() + 1, 0);
  for (std::size_t q = 0; q < points.size(); ++q) begin[q + 1] = begin[q] + static_cast<std::uint32_t>(points[q].size());
  prepare_with(grid, begin, &points, own_depth, s, targets, store, device_points);
}

void VulkanRadianceRaster::prepare_from_rays(const probes::ProbeGrid& grid, const std::vector<const probes::DepthMap*>& own_depth,
                                             const probes::SharingSettings& s, std::span<const std::uint8_t> targets,
                                             VulkanMapStore* store, const DevicePoints& rays) {
  const auto count = static_cast<std::size_t>(grid.count());
  std::vector<std::uint32_t> per(count, 0), begin(count + 1, 0);
  for (const int q : rays.tracing) {
    if (q < 0 || static_cast<std::size_t>(q) >= count || per[static_cast<std::size_t>(q)] != 0)
      throw std::invalid_argument("VulkanRadianceRaster::prepare_from_rays: probe " + std::to_string(q) +
                                  " out of the grid or traced twice");
    per[static_cast<std::size_t>(q)] = rays.rays_per_probe;
  }
  for (std::size_t q = 0; q < count; ++q) begin[q + 1] = begin[q] + per[q];
  prepare_with(grid, begin, nullptr, own_depth, s, targets, store, &rays);
}

void VulkanRadianceRaster::prepare_with(const probes::ProbeGrid& grid, const std::vector<std::uint32_t>& begin,
                                        const std::vector<std::vector<probes::ShadedPoint>>* host_points,
                                        const std::vector<const probes::DepthMap*>& own_depth, const probes::SharingSettings& s,
                                        std::span<const std::uint8_t> targets, VulkanMapStore* store,
                                        const DevicePoints* device_points) {
  const auto count = static_cast<std::size_t>(grid.count());
  const auto texels = static_cast<std::size_t>(layout_.texel_count());
  if (begin.size() != count + 1 || (!own_depth.empty() && own_depth.size() != count) ||
      (!targets.empty() && targets.size() != count) || (!grid.offsets.empty() && grid.offsets.size() != count))
    throw std::invalid_argument("VulkanRadianceRaster: " + std::to_string(count) + " probes but points for " +
                                std::to_string(begin.size() - 1) + ", depth for " + std::to_string(own_depth.size()) +
                                ", " + std::to_string(targets.size()) + " target flags");
  count_ = count;
  if (store && (static_cast<std::size_t>(store->probes()) != count || store->layout().texel_count() != layout_.texel_count()))
    throw std::invalid_argument("VulkanRadianceRaster: a map store of " + std::to_string(store->probes()) + " probes for a grid of " +
                                std::to_string(count));
  store_ = store && !own_depth.empty() ? store : nullptr;  // no depth maps given: none to read

  // Inputs go straight into the mapped buffers and results come straight out,
  // in parallel over probes: tens of MB of depth maps and samples a frame,
  // which serial copies made cost several times the kernel on an H100.
  // A depth guard needs every probe's map; a probe without one (null) reads
  // as "never hit" (NaN), which the guard lets through, as the CPU does.
  const bool has_depth = !own_depth.empty();
  // Without a store every map is written here; with one, only the changed go up.
  const bool write_depth = has_depth && !store_;
  const std::size_t depth_texels = write_depth ? count * texels : 1;
  std::vector<ProbeGpu> info(count);
  std::vector<std::uint32_t>& target_flags = target_flags_;
  target_flags.assign(count, 1);
  for (std::size_t q = 0; q < count; ++q) {
    const probes::DepthMap* d = has_depth ? own_depth[q] : nullptr;
    const glm::vec3 off = grid.offsets.empty() ? glm::vec3(0.0f) : grid.offsets[q];
    info[q] = {off.x, off.y, off.z, d ? d->unit : 1.0f, 0, 0, 0, 0};
    if (!targets.empty()) target_flags[q] = targets[q] ? 1u : 0u;
  }
  using DepthTexel = probes::DepthMap::Texel;
  point_groups_ = 0;
  points_on_device_ = false;
  bool on_device = false;
  if (!host_points) {
    std::vector<std::uint32_t> first;
    for (const int q : device_points->tracing) first.push_back(begin[static_cast<std::size_t>(q)]);
    bind_rays_as_points(*device_points, begin, first);
    on_device = true;
  } else {
    on_device = device_points && bind_device_points(*host_points, *device_points, begin);
  }
  if (!on_device) {
    engine::gpu::bind_at_least(ctx_, *pipeline_, 0, points_, std::max<std::size_t>(1, begin[count]) * sizeof(ShadedPointGpu));
    pipeline_->bind(0, points_);  // device_points_ may have been bound since
  }
  const auto flat = on_device ? std::span<ShadedPointGpu>() : points_.mapped_as<ShadedPointGpu>(begin[count]);
  bind_depth(own_depth, depth_texels);
  const auto depth = write_depth ? depth_.mapped_as<DepthTexel>(depth_texels) : std::span<DepthTexel>();
  engine::jobs::parallel_for<std::size_t>(0, count, 8, [&](std::size_t q0, std::size_t q1) {
    for (std::size_t q = q0; q < q1; ++q) {
      std::size_t i = begin[q];
      for (const auto& pt : on_device ? std::span<const probes::ShadedPoint>() : std::span<const probes::ShadedPoint>((*host_points)[q]))
        flat[i++] = {pt.position.x, pt.position.y, pt.position.z, pt.distance, pt.radiance.x, pt.radiance.y,
                     pt.radiance.z, 0, pt.direction.x, pt.direction.y, pt.direction.z, 0, pt.normal.x, pt.normal.y,
                     pt.normal.z, 0};
      if (!write_depth) continue;
      const probes::DepthMap* d = own_depth[q];
      if (d && d->texels.size() == texels) std::memcpy(&depth[q * texels], d->texels.data(), texels * sizeof(DepthTexel));
      else std::fill_n(&depth[q * texels], texels, DepthTexel{});
    }
  });
  engine::gpu::bind_at_least(ctx_, *pipeline_, 1, ranges_, begin.size() * sizeof(std::uint32_t)).upload(std::span<const std::uint32_t>(begin));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 3, probes_, info.size() * sizeof(ProbeGpu)).upload(std::span<const ProbeGpu>(info));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 4, targets_, target_flags.size() * sizeof(std::uint32_t)).upload(std::span<const std::uint32_t>(target_flags));
  engine::gpu::bind_at_least(ctx_, *pipeline_, 5, samples_, count * texels * 4 * sizeof(float));
  const std::uint32_t zero[2] = {0, 0};
  engine::gpu::bind_at_least(ctx_, *pipeline_, 6, stats_, sizeof(zero)).upload(std::span<const std::uint32_t>(zero));

  RasterPush push{};
  push.grid = probe_grid_gpu(grid);
  push.relative_tolerance = s.relative_tolerance;
  push.absolute_tolerance = s.absolute_tolerance;
  push.spread_tolerance = s.spread_tolerance;
  const bool guard = s.mode == probes::SharingMode::DepthGuard;
  push.flags = (guard ? kRasterDepthGuard : 0u) | (s.same_side ? kRasterSameSide : 0u) | (has_depth ? kRasterHasDepth : 0u) |
               (grid.offsets.empty() ? 0u : kRasterHasOffsets);
  push.map_width = static_cast<uint>(layout_.width);
  push.map_height = static_cast<uint>(layout_.height);
  push.texels = static_cast<uint>(texels);
  push_.assign(reinterpret_cast<const std::uint8_t*>(&push), reinterpret_cast<const std::uint8_t*>(&push) + sizeof(push));
}

bool VulkanRadianceRaster::takes_device_points(const std::vector<std::vector<probes::ShadedPoint>>& points,
                                               const DevicePoints& rays) {
  std::vector<std::uint32_t> begin(points.size() + 1, 0), first;
  for (std::size_t q = 0; q < points.size(); ++q) begin[q + 1] = begin[q] + static_cast<std::uint32_t>(points[q].size());
  return points_from_rays(points, rays, begin, first);
}

void VulkanRadianceRaster::record(VkCommandBuffer cmd, const VulkanProbeOwnDepth* own_depth) const {
  if (store_) store_->record_depth_uploads(cmd);
  if (own_depth) {
    own_depth->record(cmd);
    engine::gpu::record_compute_barrier(cmd);
  }
  if (point_groups_ > 0) {
    points_pipeline_->record_dispatch(cmd, point_groups_, 1, 1, point_push_);
    engine::gpu::record_compute_barrier(cmd);
  }
  if (count_ > 0) pipeline_->record_dispatch(cmd, static_cast<std::uint32_t>(count_), 1, 1, push_.data());
}

probes::SharingStats VulkanRadianceRaster::finish(std::vector<probes::FrameSamples>* out) const {
  const std::size_t count = count_, texels = static_cast<std::size_t>(layout_.texel_count());
  if (out) {
    out->resize(count);
    const auto samples = samples_.mapped_as<const float>(count * texels * 4);
    engine::jobs::parallel_for<std::size_t>(0, count, 8, [&](std::size_t q0, std::size_t q1) {
      for (std::size_t q = q0; q < q1; ++q) {
        if (!target_flags_[q]) continue;
        auto& fs = (*out)[q];
        fs.reset(static_cast<int>(texels));
        for (std::size_t t = 0; t < texels; ++t) {
          const float* v = &samples[(q * texels + t) * 4];
          fs.sum[t] = glm::vec3(v[0], v[1], v[2]);
          fs.count[t] = v[3];
        }
      }
    });
  }
  std::uint32_t stats[2];
  stats_.download(std::span<std::uint32_t>(stats));
  return {stats[0], stats[1]};
}

probes::SharingStats VulkanRadianceRaster::rasterize(const probes::ProbeGrid& grid,
                                                     const std::vector<std::vector<probes::ShadedPoint>>& points,
                                                     const std::vector<const probes::DepthMap*>& own_depth,
                                                     const probes::SharingSettings& s,
                                                     std::vector<probes::FrameSamples>& out,
                                                     std::span<const std::uint8_t> targets, double* gpu_ms) {
  prepare(grid, points, own_depth, s, targets);
  const double ms = ctx_.submit_and_wait([&](VkCommandBuffer cmd) { record(cmd); });
  if (gpu_ms) *gpu_ms = ms;
  return finish(&out);
}

}  // namespace transgi::gpu
