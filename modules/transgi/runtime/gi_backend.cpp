#include "runtime/gi_backend.h"

#include "gpu/vulkan_probe_kernels.h"
#include "probes/cpu_probe_kernels.h"

namespace transgi::runtime {

namespace {

class CpuGiBackend final : public GiBackend {
 public:
  [[nodiscard]] std::shared_ptr<probes::ProbeKernels> probe_kernels() const override { return probes::cpu_probe_kernels(); }
  [[nodiscard]] engine::rt::RayBatchTracer* tracer() override { return nullptr; }
  shading::TransferBatchDecoder* transfer_decoder(const std::shared_ptr<const model::TransferModel>&, std::string*) override {
    return nullptr;
  }
  std::vector<DeviceStageTime> take_probe_stage_times() override { return {}; }
  engine::gpu::GpuTraffic take_traffic() override { return {}; }
  [[nodiscard]] std::string name() const override { return "cpu"; }
};

class VulkanGiBackend final : public GiBackend {
 public:
  explicit VulkanGiBackend(std::shared_ptr<gpu::VulkanProbeKernels> kernels) : kernels_(std::move(kernels)) {}
  [[nodiscard]] std::shared_ptr<probes::ProbeKernels> probe_kernels() const override { return kernels_; }
  [[nodiscard]] engine::rt::RayBatchTracer* tracer() override { return kernels_->tracer(); }
  shading::TransferBatchDecoder* transfer_decoder(const std::shared_ptr<const model::TransferModel>& model,
                                                  std::string* why) override {
    shading::TransferBatchDecoder* decoder = kernels_->transfer_decoder(model);
    if (!decoder && why) *why = kernels_->transfer_decoder_why();
    return decoder;
  }
  std::vector<DeviceStageTime> take_probe_stage_times() override {
    const gpu::VulkanProbeKernels::StageMs s = kernels_->take_stage_ms();
    return {{device_stage::kOtherRays, s.trace},      {device_stage::kProbeRays, s.shading},
            {device_stage::kRaster, s.raster},        {device_stage::kAccumulation, s.accumulation},
            {device_stage::kProjection, s.projection}};
  }
  engine::gpu::GpuTraffic take_traffic() override { return kernels_->take_traffic(); }
  [[nodiscard]] std::string name() const override { return kernels_->name(); }

 private:
  std::shared_ptr<gpu::VulkanProbeKernels> kernels_;
};

}  // namespace

std::shared_ptr<GiBackend> cpu_gi_backend() {
  static const std::shared_ptr<GiBackend> backend = std::make_shared<CpuGiBackend>();
  return backend;
}

std::shared_ptr<GiBackend> make_vulkan_gi_backend(std::shared_ptr<engine::gpu::VulkanContext> host, const std::string& device,
                                                  probes::BackendFallback* reason, std::string* why) {
  std::shared_ptr<gpu::VulkanProbeKernels> kernels =
      host ? gpu::make_probe_kernels(std::move(host), reason, why) : gpu::make_probe_kernels(device, reason, why);
  if (!kernels) return nullptr;
  return std::make_shared<VulkanGiBackend>(std::move(kernels));
}

}  // namespace transgi::runtime
