#pragma once
// probes::ProbeGrid and a probe field as the kernels read them (ProbeGridGpu,
// ProbeFieldGpu, transgi_shared.h).
#include <cstdint>
#include <span>
#include <vector>

#include "probes/interpolation.h"
#include "probes/probe_grid.h"
#include "probes/probe_map.h"
#include "transgi_shared.h"

namespace transgi::gpu {

inline ProbeGridGpu probe_grid_gpu(const probes::ProbeGrid& grid) {
  const glm::vec3 s = grid.spacing();
  return {grid.min.x,       grid.min.y,  grid.min.z,  grid.count(),  s.x,          s.y,          s.z,          grid.min_spacing(),
          grid.dims.x,      grid.dims.y, grid.dims.z, 0,             grid.scroll.x, grid.scroll.y, grid.scroll.z, 0};
}

// The interpolation's parameters for `grid` (points: 0; the caller sets it
// where the kernel counts them). viewer: the points' viewer (the camera),
// or null for none (probes::interpolate_probes).
inline InterpolatePush interpolate_push(const probes::ProbeGrid& grid, const probes::MapLayout& layout,
                                        const probes::InterpolationSettings& interpolation, const glm::vec3* viewer) {
  InterpolatePush r{};
  r.grid = probe_grid_gpu(grid);
  r.bias_length = interpolation.normal_bias * grid.min_spacing();
  r.visibility_threshold = interpolation.visibility_threshold;
  r.visibility_ramp = interpolation.visibility_ramp;
  r.flags = (interpolation.prune_back_facing ? kInterpolatePruneBackFacing : 0u) |
            (interpolation.prune_occluded ? kInterpolatePruneOccluded : 0u) |
            (grid.offsets.empty() ? 0u : kInterpolateHasOffsets);
  r.map_width = static_cast<uint>(layout.width);
  r.map_height = static_cast<uint>(layout.height);
  r.texels = static_cast<uint>(layout.texel_count());
  if (viewer && interpolation.view_bias > 0) {
    r.viewer_x = viewer->x, r.viewer_y = viewer->y, r.viewer_z = viewer->z;
    r.view_bias_length = interpolation.view_bias * grid.min_spacing();
  }
  return r;
}

// A field whose probes start at probe_base and depth texels at depth_base
// in a kernel's shared buffers: `grid` as relocated (interpolation reads
// the probes where they stand), its box, the hand-over band (in metres) and
// its points' viewer (null: none).
inline ProbeFieldGpu probe_field_gpu(const probes::ProbeGrid& grid, const probes::MapLayout& layout,
                                     const probes::InterpolationSettings& interpolation, const glm::vec3* viewer, float band,
                                     std::uint32_t probe_base, std::uint32_t depth_base) {
  ProbeFieldGpu r{};
  r.field = interpolate_push(grid, layout, interpolation, viewer);
  r.probe_base = probe_base;
  r.depth_base = depth_base;
  r.enabled = 1u;
  r.box_min_x = grid.min.x;
  r.box_min_y = grid.min.y;
  r.box_min_z = grid.min.z;
  r.band = band;
  r.box_max_x = grid.max.x;
  r.box_max_y = grid.max.y;
  r.box_max_z = grid.max.z;
  return r;
}

// A field's probes (relocation offset, depth unit, whether it holds light)
// into probes[probe_base ..] and their depth moments, `texels` a probe, into
// depth[depth_base ..] (zeros for a probe that holds none), as the
// interpolation kernels read them. usable empty: every probe. depth empty:
// the probes only (the depth goes up another way, a VulkanMapStore's copy).
void write_probe_field(const probes::ProbeGrid& grid, const std::vector<probes::ProbeMapState>& states,
                       std::span<const std::uint8_t> usable, std::size_t texels, std::size_t probe_base,
                       std::size_t depth_base, std::span<std::uint32_t> depth, std::span<ProbeGpu> probes);

}  // namespace transgi::gpu
