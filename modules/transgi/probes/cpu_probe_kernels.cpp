#include "probes/cpu_probe_kernels.h"

#include <chrono>
#include <stdexcept>
#include <string>

#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "shading/sh_light.h"

namespace transgi::probes {

const char* to_string(BackendFallback reason) {
  switch (reason) {
    case BackendFallback::None: return "none";
    case BackendFallback::NoDevice: return "no device";
    case BackendFallback::MissingCapability: return "missing capability";
    case BackendFallback::KernelBuildFailed: return "kernel build failed";
    case BackendFallback::SceneTooLarge: return "scene too large";
  }
  return "unknown";
}

glm::vec3 probe_irradiance(const ProbeFeedbackSource& s, const glm::vec3& p, const glm::vec3& n) {
  const InterpolationResult r = interpolate_probes(*s.grid, s.layout, *s.states, p, n, s.interpolation, s.usable);
  float L[75];
  for (float& v : L) v = 0.0f;
  for (std::size_t i = 0; i < 8; ++i) {
    if (r.weights[i] == 0.0f) continue;
    const float* probe = s.sh.data() + static_cast<std::size_t>(r.probes[i]) * 75;
    for (int k = 0; k < 75; ++k) L[k] += r.weights[i] * probe[k];
  }
  return shading::sh_irradiance(L, n);
}

glm::vec3 bounce_irradiance(const ProbeFeedbackSource& self, const ProbeFeedbackSource* outer, const glm::vec3& p,
                            const glm::vec3& n) {
  if (outer && (glm::any(glm::lessThan(p, self.held_min())) || glm::any(glm::greaterThan(p, self.held_max()))))
    return outer->lit ? probe_irradiance(*outer, p, n) : glm::vec3(0.0f);
  return self.lit ? probe_irradiance(self, p, n) : glm::vec3(0.0f);
}

void CpuProbeKernels::shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                       std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                                       std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                                       const ProbeFeedbackSource& self, const ProbeFeedbackSource* outer,
                                       const ProbeRayConsumer& consume) {
  trace_listed_probe_rays(
      scene, lights, origins, probe_ids, directions, seed, sample,
      [&](const glm::vec3& p, const glm::vec3& n, const glm::vec3&) { return bounce_irradiance(self, outer, p, n); }, consume);
}

SharingStats CpuProbeKernels::share_accumulate_project(const ProbeGrid& grid, const MapProjector& projector,
                                                       const std::vector<std::vector<ShadedPoint>>& points,
                                                       const std::vector<const DepthMap*>& own_depth,
                                                       const SharingSettings& sharing, std::span<const int> batch,
                                                       std::span<ProbeMapState* const> states, ProbeMapStore* store,
                                                       const AccumulationSettings& accumulation,
                                                       std::span<std::uint8_t> changed, std::span<float> sh,
                                                       ShareAccumulateTimes& times) {
  using Clock = std::chrono::steady_clock;
  const auto ms_since = [](Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); };
  if (store) throw std::invalid_argument("CpuProbeKernels: a map store from another backend");
  for (std::size_t i = 0; i < states.size(); ++i)
    if (states[i]->device_stamp != 0)
      throw std::logic_error("CpuProbeKernels: probe " + std::to_string(batch[i]) +
                             "'s maps are held on a device; read them back first (ProbeMapStore::read_back)");
  auto t0 = Clock::now();
  update_own_depths(batch, states, points, projector.layout(), accumulation);
  std::vector<std::uint8_t> targets(static_cast<std::size_t>(grid.count()), 0);
  for (const int q : batch) targets[static_cast<std::size_t>(q)] = 1;
  // Only the batch's maps are filled (and allocated).
  std::vector<FrameSamples> samples;
  const SharingStats stats = rasterize_shared(grid, projector.layout(), points, own_depth, sharing, samples, targets);
  times.share_ms = ms_since(t0);
  t0 = Clock::now();
  // One probe at a time: its filled map stays in cache for the projection.
  engine::jobs::parallel_for(0, static_cast<int>(batch.size()), 1, [&](int b, int e) {
    for (int i = b; i < e; ++i) {
      const auto k = static_cast<std::size_t>(i);
      changed[k] = accumulate(*states[k], samples[static_cast<std::size_t>(batch[k])], accumulation) ? 1 : 0;
      const std::vector<glm::vec3> filled = filled_radiance(*states[k], projector.layout(), accumulation.fill_passes);
      projector.project(filled.data(), sh.data() + k * 75);
    }
  });
  times.accumulate_ms = ms_since(t0);
  return stats;
}

std::shared_ptr<ProbeKernels> cpu_probe_kernels() {
  static const std::shared_ptr<ProbeKernels> kernels = std::make_shared<CpuProbeKernels>();
  return kernels;
}

}  // namespace transgi::probes
