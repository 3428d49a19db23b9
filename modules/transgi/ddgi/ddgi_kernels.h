#pragma once
// DDGI's data-parallel stages behind one interface, as TransGI's
// probes::ProbeKernels, with two complete implementations: the CPU backend
// (cpu_ddgi_kernels.h, the oracle) and the Vulkan backend
// (gpu/vulkan_ddgi_kernels.h). Every volume and the renderer run every stage
// through the one backend the plugin holds (DdgiBackend); a backend never
// hands a stage back. A scene the device cannot hold throws
// engine::gpu::GpuError, and the plugin then swaps in the CPU backend whole.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include <glm/mat2x3.hpp>

#include "ddgi/ddgi_blend.h"
#include "engine/gpu/vulkan_context.h"
#include "engine/image/image.h"
#include "engine/render/camera_rays.h"
#include "engine/render/light_set.h"
#include "engine/rt/ray_batch_tracer.h"
#include "probes/probe_kernels.h"
#include "probes/probe_rays.h"

namespace transgi::ddgi {

class DdgiVolume;

struct DdgiRenderSettings {
  int spp = 1;
  std::uint64_t seed = 0;
  float filter_width = 1.5f;
};

// The bounce light at a probe ray's hit: irradiance at p about n, seen from
// the probe along to_probe (DDGI's volumes from the last update).
using ProbeRayBounce = std::function<glm::vec3(const glm::vec3& p, const glm::vec3& n, const glm::vec3& to_probe)>;
using probes::ProbeRayConsumer;

class DdgiKernels {
 public:
  virtual ~DdgiKernels() = default;
  // The rays of probes origins[j] (index probe_ids[j]) along each of
  // `directions`, traced and shaded as probes::trace_probe_ray does, ray i
  // of probe q drawing from make_rng(seed, q * 4096 + i, sample), the
  // bounce light from `bounce`, each handed to `consume` (the CPU streams
  // them as they are shaded, a device hands them over after its batch). A
  // device that cannot hold the scene throws engine::gpu::GpuError.
  virtual void shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                                std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                                const ProbeRayBounce& bounce, const ProbeRayConsumer& consume) = 0;
  // The probe rays' (and the real-time G-buffer's) tracer; null = the
  // RtScene's own (Embree) queries.
  virtual engine::rt::RayBatchTracer* tracer() = 0;
  // blend_irradiance and blend_distance for every probe with records (an
  // empty list leaves that probe).
  virtual void blend(std::vector<OctahedralMap<glm::vec3>>& irradiance, std::vector<OctahedralMap<glm::vec2>>& distance,
                     const std::vector<std::vector<RayRecord>>& records, const DdgiSettings& settings, float hysteresis,
                     bool clamp_brightness, float max_distance) = 0;
  // For each point k, the volumes' light blended as irradiance_from blends
  // it: out[k][0] from the irradiance maps, out[k][1] from the emitted maps
  // (DdgiSettings::emitted_maps; 0 from a volume without them).
  virtual void irradiance(std::span<const DdgiVolume* const> volumes, std::span<const glm::vec3> positions,
                          std::span<const glm::vec3> normals, std::span<const glm::vec3> view_dirs,
                          std::span<glm::mat2x3> out) = 0;
  // The offline GI pass (ddgi_renderer.h, render_ddgi_gi).
  virtual engine::image::ImageRGB render_gi(const engine::rt::RtScene& scene, std::span<const DdgiVolume* const> volumes,
                                            const engine::render::CameraRays& camera, int width, int height,
                                            const DdgiRenderSettings& settings) = 0;
  [[nodiscard]] virtual const char* name() const = 0;
  // Submissions and bytes between host and device since the last call
  // (engine::gpu::GpuTraffic); none on the CPU.
  virtual engine::gpu::GpuTraffic take_traffic() { return {}; }
};

}  // namespace transgi::ddgi
