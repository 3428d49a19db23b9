#pragma once
// Across-probe radiance sharing in one dispatch
// (shaders/radiance_raster.comp): the contract of probes::rasterize_shared,
// which is its oracle (tests/gpu/radiance_raster_test.cpp).
#include <memory>
#include <span>
#include <vector>

#include "engine/gpu/compute_pipeline.h"
#include "engine/gpu/gpu_buffer.h"
#include "engine/gpu/vulkan_context.h"
#include "gpu/vulkan_map_store.h"
#include "gpu/vulkan_probe_own_depth.h"
#include "probes/radiance_sharing.h"

namespace transgi::gpu {

class VulkanRadianceRaster {
 public:
  VulkanRadianceRaster(engine::gpu::VulkanContext& ctx, probes::MapLayout layout);

  // As probes::rasterize_shared; *gpu_ms (if given) gets the kernel's time.
  probes::SharingStats rasterize(const probes::ProbeGrid& grid, const std::vector<std::vector<probes::ShadedPoint>>& points,
                                 const std::vector<const probes::DepthMap*>& own_depth,
                                 const probes::SharingSettings& settings, std::vector<probes::FrameSamples>& out,
                                 std::span<const std::uint8_t> targets = {}, double* gpu_ms = nullptr);

  // The same in three steps, for a submission that holds other stages too.
  // The probe rays' hits on the device, as VulkanProbeShading left them:
  // the rays of tracing probe j (rays_per_probe each, in the order of the
  // directions) are probe tracing[j]'s points.
  struct DevicePoints {
    const engine::gpu::GpuBuffer* hits = nullptr;        // ProbeRayHitGpu per ray
    const engine::gpu::GpuBuffer* directions = nullptr;  // vec4 per direction
    std::span<const int> tracing;
    std::uint32_t rays_per_probe = 0;
  };

  // prepare: the points, depth maps and targets written for the kernel.
  // With the field's `store`, the depth maps are its copies (only the
  // changed ones staged, sent by record). With `device_points` whose rays
  // are `points` (every probe's points are its rays' or none), the points
  // are made from them on the device (probe_points.comp) and not sent;
  // otherwise they go up from `points`.
  void prepare(const probes::ProbeGrid& grid, const std::vector<std::vector<probes::ShadedPoint>>& points,
               const std::vector<const probes::DepthMap*>& own_depth, const probes::SharingSettings& settings,
               std::span<const std::uint8_t> targets = {}, VulkanMapStore* store = nullptr,
               const DevicePoints* device_points = nullptr);
  // prepare where the points are, by construction, the rays' (every
  // tracing probe's rays_per_probe, no other probe's): nothing is read of
  // the host's points, which need not exist yet (a submission that traces
  // the rays and rasterises their points at once).
  void prepare_from_rays(const probes::ProbeGrid& grid, const std::vector<const probes::DepthMap*>& own_depth,
                         const probes::SharingSettings& settings, std::span<const std::uint8_t> targets,
                         VulkanMapStore* store, const DevicePoints& rays);
  // Whether the last prepare made the points on the device.
  [[nodiscard]] bool points_made_on_device() const { return points_on_device_; }
  // Whether prepare would make these points on the device from `rays`.
  [[nodiscard]] static bool takes_device_points(const std::vector<std::vector<probes::ShadedPoint>>& points,
                                                const DevicePoints& rays);
  // record: the store's depth uploads and the dispatch, into a command
  // buffer being recorded; with `own_depth`, its update of the store's
  // depth maps between the two.
  void record(VkCommandBuffer cmd, const VulkanProbeOwnDepth* own_depth = nullptr) const;
  // The samples on the device after the submission: vec4 (sum, count) per
  // texel, one map per probe of the grid (the targets' written).
  [[nodiscard]] const engine::gpu::GpuBuffer& samples_on_device() const { return samples_; }
  // After the submission: the guard's counts; with `out`, the targets'
  // samples read back (out resized to the grid's probes).
  probes::SharingStats finish(std::vector<probes::FrameSamples>* out) const;

 private:
  // prepare's steps. The points made on the device from `rays` where they
  // are `points` (probe_points.comp bound, the raster reading its output);
  // false: not, nothing bound.
  bool bind_device_points(const std::vector<std::vector<probes::ShadedPoint>>& points, const DevicePoints& rays,
                          const std::vector<std::uint32_t>& begin);
  // probe_points.comp bound for `rays`, tracing probe j's points from first[j].
  void bind_rays_as_points(const DevicePoints& rays, const std::vector<std::uint32_t>& begin, const std::vector<std::uint32_t>& first);
  // prepare's body: probe q's points at begin[q], from `host_points` (null:
  // made from `device_points`, which are then the points).
  void prepare_with(const probes::ProbeGrid& grid, const std::vector<std::uint32_t>& begin,
                    const std::vector<std::vector<probes::ShadedPoint>>* host_points,
                    const std::vector<const probes::DepthMap*>& own_depth, const probes::SharingSettings& settings,
                    std::span<const std::uint8_t> targets, VulkanMapStore* store, const DevicePoints* device_points);
  // The depth maps the raster reads: the store's copies (the changed ones
  // staged), or host_texels texels written here.
  void bind_depth(const std::vector<const probes::DepthMap*>& own_depth, std::size_t host_texels);

  engine::gpu::VulkanContext& ctx_;
  probes::MapLayout layout_;
  engine::gpu::GpuBuffer points_, ranges_, depth_, probes_, targets_, samples_, stats_;
  std::unique_ptr<engine::gpu::ComputePipeline> pipeline_;
  std::size_t count_ = 0;                 // the prepared grid's probes
  VulkanMapStore* store_ = nullptr;  // the prepared update's, if any
  // The points made on the device: probe_points.comp, its output, and the
  // prepared dispatch (0 groups: the points went up from the host).
  std::unique_ptr<engine::gpu::ComputePipeline> points_pipeline_;
  engine::gpu::GpuBuffer device_points_, first_point_;
  std::uint32_t point_groups_ = 0, point_push_[2] = {0, 0};
  bool points_on_device_ = false;
  std::vector<std::uint32_t> target_flags_;
  std::vector<std::uint8_t> push_;
};

}  // namespace transgi::gpu
