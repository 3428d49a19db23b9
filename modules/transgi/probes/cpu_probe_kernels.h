#pragma once
// The probe field's stages on the CPU (probes::ProbeKernels): Embree's rays,
// the job system's threads. The oracle the Vulkan backend is tested against,
// and the backend every field holds unless a device is chosen.
#include <memory>

#include "probes/probe_kernels.h"

namespace transgi::probes {

class CpuProbeKernels final : public ProbeKernels {
 public:
  void shade_probe_rays(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                        std::span<const glm::vec3> origins, std::span<const int> probe_ids,
                        std::span<const glm::vec3> directions, std::uint64_t seed, std::uint64_t sample,
                        const ProbeFeedbackSource& self, const ProbeFeedbackSource* outer,
                        const ProbeRayConsumer& consume) override;
  SharingStats share_accumulate_project(const ProbeGrid& grid, const MapProjector& projector,
                                        const std::vector<std::vector<ShadedPoint>>& points,
                                        const std::vector<const DepthMap*>& own_depth, const SharingSettings& sharing,
                                        std::span<const int> batch, std::span<ProbeMapState* const> states,
                                        ProbeMapStore* store, const AccumulationSettings& accumulation, std::span<std::uint8_t> changed,
                                        std::span<float> sh, ShareAccumulateTimes& times) override;
  // The maps live in the ProbeMapStates: no store.
  [[nodiscard]] std::unique_ptr<ProbeMapStore> make_map_store(const MapLayout&, int) override { return nullptr; }
  engine::rt::RayBatchTracer* tracer() override { return nullptr; }
  [[nodiscard]] const char* name() const override { return "cpu"; }
};

// The one CPU backend, shared by every field that is given no other.
std::shared_ptr<ProbeKernels> cpu_probe_kernels();

}  // namespace transgi::probes
