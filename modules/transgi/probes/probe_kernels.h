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

#include "engine/render/light_set.h"
#include "engine/rt/ray_batch_tracer.h"
#include "engine/rt/rt_scene.h"
#include "probes/interpolation.h"
#include "probes/probe_map.h"
#include "probes/probe_rays.h"
#include "probes/radiance_sharing.h"

namespace transgi::probes {

// A probe field as the bounce light of probe rays reads it
// (ProbeField::irradiance): its relocated grid, maps, SH and usable flags.
struct ProbeFeedbackSource {
  const ProbeGrid* grid = nullptr;
  MapLayout layout;
  const std::vector<ProbeMapState>* states = nullptr;
  std::span<const float> sh;                // probes x 75
  std::span<const std::uint8_t> usable;     // probes
  InterpolationSettings interpolation;
};

class ProbeKernels {
 public:
  virtual ~ProbeKernels() = default;
  // As rasterize_shared.
  virtual SharingStats rasterize(const ProbeGrid& grid, const MapLayout& layout,
                                 const std::vector<std::vector<ShadedPoint>>& points,
                                 const std::vector<const DepthMap*>& own_depth, const SharingSettings& settings,
                                 std::vector<FrameSamples>& out, std::span<const std::uint8_t> targets) = 0;
  // For each i: accumulate(*states[i], *frames[i], settings) (changed[i] its
  // result), then filled_radiance(*states[i], layout, settings.fill_passes)
  // into filled (states.size() x texel_count()). Returns false, touching
  // nothing, where the backend does not accumulate (the caller does).
  virtual bool accumulate(const MapLayout& /*layout*/, std::span<ProbeMapState* const> /*states*/,
                          std::span<const FrameSamples* const> /*frames*/, const AccumulationSettings& /*settings*/,
                          std::span<std::uint8_t> /*changed*/, std::span<glm::vec3> /*filled*/) {
    return false;
  }
  // As MapProjector::project for `maps` maps stored one after another:
  // radiance maps x texel_count(), out maps x 75.
  virtual void project(const MapProjector& projector, std::span<const glm::vec3> radiance, std::span<float> out) = 0;
  // Traces and shades the rays of probes origins[j] (index probe_ids[j])
  // along each of `directions` as trace_probe_rays does, ray i of probe q
  // drawing from make_rng(seed, q * 4096 + i, sample), the bounce light from
  // `self` inside its grid's box and from `outer` beyond it (null: none).
  // out: origins.size() x directions.size(), probe-major. Returns false, out
  // untouched, where the backend does not shade (the caller then shades on
  // the CPU).
  virtual bool shade_probe_rays(const engine::rt::RtScene& /*scene*/, const engine::render::LightSet& /*lights*/,
                                std::span<const glm::vec3> /*origins*/, std::span<const int> /*probe_ids*/,
                                std::span<const glm::vec3> /*directions*/, std::uint64_t /*seed*/, std::uint64_t /*sample*/,
                                const ProbeFeedbackSource* /*self*/, const ProbeFeedbackSource* /*outer*/,
                                std::vector<ProbeRayHit>& /*out*/) {
    return false;
  }
  // The backend's ray tracer for the probe rays (and the G-buffer's camera
  // rays); null = Embree.
  virtual engine::rt::RayBatchTracer* tracer() = 0;
  [[nodiscard]] virtual const char* name() const = 0;
};

}  // namespace transgi::probes
