#include "gpu/probe_grid_gpu.h"

#include <cstring>

#include "engine/jobs/parallel_for.h"

namespace transgi::gpu {

void write_probe_field(const probes::ProbeGrid& grid, const std::vector<probes::ProbeMapState>& states,
                       std::span<const std::uint8_t> usable, std::size_t texels, std::size_t probe_base,
                       std::size_t depth_base, std::span<std::uint32_t> depth, std::span<ProbeGpu> probes) {
  // Depth texels are two binary16 (mean, variance): exactly a GLSL half2.
  static_assert(sizeof(probes::DepthMap::Texel) == 4);
  engine::jobs::parallel_for<std::size_t>(0, states.size(), 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t q = b; q < e; ++q) {
      const probes::DepthMap& d = states[q].depth;
      const bool holds = usable.empty() || usable[q] != 0;
      if (!depth.empty()) {
        std::uint32_t* dst = depth.data() + depth_base + q * texels;
        if (holds && d.texels.size() == texels) std::memcpy(dst, d.texels.data(), texels * 4);
        else std::memset(dst, 0, texels * 4);
      }
      const glm::vec3 off = grid.offsets.empty() ? glm::vec3(0.0f) : grid.offsets[q];
      probes[probe_base + q] = {off.x, off.y, off.z, d.unit, holds ? 1u : 0u, 0, 0, 0};
    }
  });
}

}  // namespace transgi::gpu
