#pragma once
// Where the TransGI frame's data-parallel work runs, chosen once by the
// plugin (pbrt-v4's aggregate with a CPU and a GPU implementation): the probe
// stages (probes::ProbeKernels), the tracer of the G-buffer's camera and
// shadow rays, the real-time transfer decoder, and what the device reports
// (its time per stage and the traffic across the bus). The plugin asks the
// backend, never a device type.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "engine/gpu/vulkan_context.h"
#include "engine/rt/ray_batch_tracer.h"
#include "model/transfer_model.h"
#include "probes/probe_kernels.h"
#include "shading/transfer_batch_decoder.h"

namespace transgi::runtime {

// A device's time for one stage of the frame, by timestamps.
struct DeviceStageTime {
  std::string name;
  double ms = 0.0;
};

// The names the backends and the frame use for the device stages (bench-frame
// prints them and writes its CSV columns from them).
namespace device_stage {
inline constexpr const char* kGbufferRays = "G-buffer rays";  // camera rays and the direct light's shadow rays
inline constexpr const char* kOtherRays = "other rays";       // traced through the tracer since the last G-buffer
inline constexpr const char* kProbeRays = "probe rays made, traced and shaded";
inline constexpr const char* kRaster = "radiance raster";
inline constexpr const char* kAccumulation = "accumulation";
inline constexpr const char* kProjection = "SH projection";
inline constexpr const char* kInference = "inference";  // the fused decoder and the SH dots
}  // namespace device_stage

class GiBackend {
 public:
  virtual ~GiBackend() = default;
  [[nodiscard]] virtual std::shared_ptr<probes::ProbeKernels> probe_kernels() const = 0;
  // The camera and shadow rays' tracer; null = the RtScene's own (Embree).
  [[nodiscard]] virtual engine::rt::RayBatchTracer* tracer() = 0;
  // The real-time frame's batch decoder for `model`, where this backend
  // decodes on its device; null = the CPU's fused kernel decodes (the CPU
  // backend's answer; a device's where its kernel cannot hold the network,
  // and then *why says so).
  virtual shading::TransferBatchDecoder* transfer_decoder(const std::shared_ptr<const model::TransferModel>& model,
                                                          std::string* why) = 0;
  // The probe stages' device times since the last call, in the order they
  // ran; empty on the CPU (its stage times are the frame's host times).
  virtual std::vector<DeviceStageTime> take_probe_stage_times() = 0;
  // Submissions and bytes between host and device since the last call; 0
  // on the CPU.
  virtual engine::gpu::GpuTraffic take_traffic() = 0;
  // "cpu", or the device as the Vulkan context describes it.
  [[nodiscard]] virtual std::string name() const = 0;
};

// The CPU backend, shared.
std::shared_ptr<GiBackend> cpu_gi_backend();

// The Vulkan backend on `host` (a device the caller made, e.g. the game's
// window's) or else on the device named (empty: ENGINE_GPU_DEVICE, then the
// ranked default); null where the device cannot run every stage, with
// *reason and *why saying why (the plugin then runs the CPU backend whole).
std::shared_ptr<GiBackend> make_vulkan_gi_backend(std::shared_ptr<engine::gpu::VulkanContext> host, const std::string& device,
                                                  probes::BackendFallback* reason, std::string* why);

}  // namespace transgi::runtime
