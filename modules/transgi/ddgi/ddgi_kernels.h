#pragma once
// DDGI's data-parallel stages behind one interface, as TransGI's
// probes::ProbeKernels: the probe rays' tracing and the per-probe blend. A
// DdgiVolume without kernels runs the CPU functions (the oracle); the
// Vulkan backend is gpu/vulkan_ddgi_kernels.h.
#include <cstdint>
#include <span>
#include <vector>

#include "ddgi/ddgi_blend.h"
#include "engine/rt/ray_batch_tracer.h"

namespace transgi::ddgi {

class DdgiKernels {
 public:
  virtual ~DdgiKernels() = default;
  // The probe rays' tracer; null = Embree.
  virtual engine::rt::RayBatchTracer* tracer() = 0;
  // blend_irradiance and blend_distance for every probe with records (an
  // empty list leaves that probe).
  virtual void blend(std::vector<OctahedralMap<glm::vec3>>& irradiance, std::vector<OctahedralMap<glm::vec2>>& distance,
                     const std::vector<std::vector<RayRecord>>& records, const DdgiSettings& settings, float hysteresis,
                     bool clamp_brightness, float max_distance) = 0;
  // DdgiVolume::irradiance at each point (out[i]; 0 where no active probe
  // weighs in, and lit[i] = 0 then, else 1). Returns false, out and lit
  // untouched, where the backend cannot.
  virtual bool irradiance(const DdgiVolume& volume, std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                          std::span<const glm::vec3> view_dirs, std::span<glm::vec3> out, std::span<std::uint8_t> lit) = 0;
  [[nodiscard]] virtual const char* name() const = 0;
};

}  // namespace transgi::ddgi
