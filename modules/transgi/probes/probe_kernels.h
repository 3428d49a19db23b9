#pragma once
// The probe field's data-parallel stages (ray tracing, raster, SH projection)
// behind one interface, so a backend
// can run them elsewhere (pbrt's split of interface and backend). The CPU
// functions (rasterize_shared, MapProjector) are the oracle; a ProbeField
// without kernels calls them directly. The Vulkan backend is
// gpu/vulkan_probe_kernels.h.
#include <cstdint>
#include <span>
#include <vector>

#include "engine/rt/ray_batch_tracer.h"
#include "probes/radiance_sharing.h"

namespace transgi::probes {

class ProbeKernels {
 public:
  virtual ~ProbeKernels() = default;
  // As rasterize_shared.
  virtual SharingStats rasterize(const ProbeGrid& grid, const MapLayout& layout,
                                 const std::vector<std::vector<ShadedPoint>>& points,
                                 const std::vector<const DepthMap*>& own_depth, const SharingSettings& settings,
                                 std::vector<FrameSamples>& out, std::span<const std::uint8_t> targets) = 0;
  // As MapProjector::project for `maps` maps stored one after another:
  // radiance maps x texel_count(), out maps x 75.
  virtual void project(const MapProjector& projector, std::span<const glm::vec3> radiance, std::span<float> out) = 0;
  // The backend's ray tracer for the probe rays (and the G-buffer's camera
  // rays); null = Embree.
  virtual engine::rt::RayBatchTracer* tracer() = 0;
  [[nodiscard]] virtual const char* name() const = 0;
};

}  // namespace transgi::probes
