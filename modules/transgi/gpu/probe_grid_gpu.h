#pragma once
// probes::ProbeGrid as the kernels read it (ProbeGridGpu, transgi_shared.h).
#include "probes/probe_grid.h"
#include "transgi_shared.h"

namespace transgi::gpu {

inline ProbeGridGpu probe_grid_gpu(const probes::ProbeGrid& grid) {
  const glm::vec3 s = grid.spacing();
  return {grid.min.x,       grid.min.y,  grid.min.z,  grid.count(),  s.x,          s.y,          s.z,          grid.min_spacing(),
          grid.dims.x,      grid.dims.y, grid.dims.z, 0,             grid.scroll.x, grid.scroll.y, grid.scroll.z, 0};
}

}  // namespace transgi::gpu
