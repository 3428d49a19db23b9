#pragma once
#include <string>
#include <string_view>
// The GI renderer's per-frame output and what it cost, read by the game,
// tools and the CLI after the Render phase.
#include <cstddef>
#include <vector>

#include "engine/ecs/entity.h"
#include "engine/image/image.h"
#include "probes/probe_field.h"
#include "runtime/gi_backend.h"
#include "shading/realtime_direct.h"
#include "shading/realtime_gi.h"

namespace transgi::runtime {

// Per-stage times in milliseconds, the rows of the paper's Table 4.
struct GiStageTimes {
  double gbuffer = 0;          // primary rays (part of "generate network input" in the paper)
  double network_input = 0;    // latent interpolation and input assembly
  double inference = 0;        // network inference
  double collect_points = 0;   // probe rays + shading of their hits
  double probe_raster = 0;     // radiance sharing into the probes' maps
  double probe_projection = 0; // accumulation and SH projection
  double sh_multiplication = 0;  // probe interpolation, SH rotation and dot product
  double direct = 0;           // direct light (not TransGI's)
  double upsample = 0;         // real-time path: choosing decoded pixels and upsampling (0 on the quality path)
  double reflections = 0;      // real-time path: metals' and glossy dielectrics' reflection rays and their filter
  double antialiasing = 0;     // real-time path: the temporal antialiasing's resolve (0 when off)
};

struct GiFrame {
  // Output size; 0 = update the probes but render no image this frame.
  int width = 0, height = 0;
  engine::ecs::Entity camera;  // null = the first camera found
  // Set for a frame that does not follow the one before (a camera cut, a
  // teleport, a loaded save): the real-time path forgets its histories (the
  // antialiasing's, the GI reuse's) for it instead of rejecting them pixel
  // by pixel. Cleared once that frame is rendered.
  bool camera_cut = false;
  // Real-time path with antialiasing: the gi and direct passes are
  // resolved with the full image (each clamped by its own neighbours), for
  // a caller that shows or measures them (render, eval, a debug view).
  // Off, only the full image is: what a player sees, at a third of the
  // resolve's cost; the passes are then each frame's own, one sample per
  // pixel, aliased on thin geometry.
  bool antialias_passes = false;

  // Results of the last rendered frame.
  engine::image::ImageRGB gi, direct, full;
  GiStageTimes times;
  std::size_t shaded_samples = 0, inferred_samples = 0;
  // This frame's probe update (summed over volumes).
  probes::ProbeFrameStats probe_stats;
  // The same per cascade (ProbeCascades), finest first; empty without them.
  std::vector<probes::ProbeFrameStats> cascade_stats;
  int cascade_probes_entered = 0;  // probes that entered by scrolling this frame
  std::uint64_t probe_frames = 0;
  // Real-time path only: decoded pixels, rotations and their times.
  shading::RealtimeGiStats realtime;
  // Deterministic direct light only: its shadow rays.
  shading::RealtimeDirectStats direct_stats;
  // Which backend ran the probe kernels ("cpu", or "vulkan" with the
  // device), and why not the one asked for, if it could not.
  std::string backend = "cpu";
  std::string backend_fallback;
  probes::BackendFallback backend_fallback_reason = probes::BackendFallback::None;
  // The backend's device time per stage, by timestamps, as the backend
  // names them (runtime::device_stage): the probe stages in the order they
  // ran, then the real-time G-buffer's rays and the inference. Empty on the
  // CPU backend.
  std::vector<DeviceStageTime> device_stages;
  // Host-device traffic since the last image (the probe updates and this
  // image; engine::gpu::GpuTraffic says how it is counted): command buffers
  // submitted, bytes written to the device and read back. 0 on the CPU.
  std::uint64_t gpu_submissions = 0, gpu_upload_bytes = 0, gpu_download_bytes = 0;
  // The device's total over its stages.
  [[nodiscard]] double gpu_ms() const {
    double ms = 0.0;
    for (const DeviceStageTime& s : device_stages) ms += s.ms;
    return ms;
  }
  // The device time of the stage named so (0 where there is none).
  [[nodiscard]] double device_stage_ms(std::string_view name) const {
    for (const DeviceStageTime& s : device_stages)
      if (s.name == name) return s.ms;
    return 0.0;
  }
  // Sets the stage named so, keeping its place in the list (appended when new).
  void set_device_stage(std::string_view name, double ms) {
    for (DeviceStageTime& s : device_stages)
      if (s.name == name) {
        s.ms = ms;
        return;
      }
    device_stages.push_back({std::string(name), ms});
  }
};

}  // namespace transgi::runtime
