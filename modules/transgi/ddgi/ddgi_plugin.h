#pragma once
// The DDGI baseline as an opt-in engine plugin, shaped like TransGIPlugin so
// the two are compared in one engine: a DdgiProbeVolume component, the
// DdgiSettings resource, and a DdgiFrame with the images and stage times.
//
//  PrepareRender  ddgi::sync_volumes: each DdgiProbeVolume has a volume for the
//                 current settings and bounds (fitted to the scene once), and
//                 each DdgiCascades one per cascade on the camera (scrolled).
//  Render         ddgi::queue_camera_view: on a device that rasterises, the
//                 real-time camera view queued to be drawn with the next
//                 submission (the probe rays').
//                 ddgi::update_volumes: rays traced, irradiance and distance blended.
//                 ddgi::render: if DdgiFrame has a size, its gi / direct / full
//                 images and stage times are this frame's.
#include <memory>

#include "ddgi/cpu_ddgi_kernels.h"
#include "ddgi/ddgi_kernels.h"
#include "probes/probe_kernels.h"
#include "ddgi/ddgi_volume.h"
#include "shading/realtime_gi.h"
#include "probes/cascade_follow.h"
#include "engine/app/app.h"
#include "engine/image/image.h"
#include "engine/render/temporal_aa.h"

namespace transgi::ddgi {

struct DdgiProbeVolume {
  glm::vec3 min{1.0f}, max{-1.0f};  // min > max: fit to the scene
  glm::ivec3 dims{8};
  std::shared_ptr<DdgiVolume> volume = nullptr;  // written by the plugin only
  [[nodiscard]] bool fits_scene() const { return glm::any(glm::greaterThan(min, max)); }
};

// DDGI's probes where the viewer is: the same cascades as TransGI's
// ProbeCascades (probes/cascade_follow.h), of DDGI volumes. A DdgiProbeVolume
// with explicit bounds takes precedence inside it.
struct DdgiCascades {
  probes::CascadeSettings cascades;
  probes::CascadeState<DdgiVolume> state{};  // written by the plugin only
};

struct DdgiRenderOptions {
  // On = the real-time frame's shape, for the game: one G-buffer ray through
  // each pixel centre, every punctual light's direct light deterministic
  // with TransGI's soft sun shadows (shading/realtime_direct.h), and DDGI's
  // light per pixel (shade_ddgi_gbuffer); gbuffer_spp, direct_spp and
  // temporal_window are then unused. Pair it with DdgiSettings::emitted_maps,
  // which bring the sky's and the emitters' direct light. Off = the offline
  // shape that eval compares: filtered rays and path-traced direct samples.
  bool realtime = false;
  // With realtime: the grid DDGI's irradiance is looked up on and how it is
  // upsampled, as TransGI's (only resolution_scale and the upsampling's
  // fields are read). resolution_scale 1 = a lookup at every pixel.
  shading::RealtimeGiSettings upsampling{};
  // With realtime: the same temporal antialiasing as TransGI's real-time
  // frame (jittered G-buffer, reprojected history, a still view's cycle
  // mean), over the full image, and over the gi and direct passes when
  // antialias_passes. Off = one ray through each pixel centre, aliased.
  engine::render::TemporalAaSettings taa{.enabled = true};
  bool antialias_passes = false;
  int gbuffer_spp = 1;  // higher = antialiased edges, at the cost of that many irradiance lookups
  int direct_spp = 4;   // higher = less direct-light noise, at the cost of tracing time; 0 = GI only
  // While the view is still, the GI image is the mean of the last this many
  // jittered frames (as TransGI's TransGISettings::temporal_window). 1 = off.
  int temporal_window = 1;
  std::uint64_t seed = 0;
};

struct DdgiStageTimes {
  // shading: DDGI's light at the pixels. direct: the direct light (with
  // DdgiRenderOptions::realtime, the G-buffer it is shaded in as well).
  double probe_trace = 0, probe_blend = 0, shading = 0, direct = 0, antialiasing = 0;
};

// Where the DDGI volumes trace and blend and the renderer looks up their
// light: the CPU backend by default; a device's is set here by whoever made
// it (gpu::make_ddgi_backend, from the CLI's --backend vulkan), and every
// volume follows it from its next update. Where a device was asked for and
// the CPU runs instead, `fallback` says why.
struct DdgiBackend {
  std::shared_ptr<DdgiKernels> kernels = cpu_ddgi_kernels();  // never null
  probes::BackendFallback fallback = probes::BackendFallback::None;
  std::string fallback_why;
  // The CPU backend whole from now on, and why.
  void fall_back(probes::BackendFallback reason, std::string why) {
    kernels = cpu_ddgi_kernels();
    fallback = reason;
    fallback_why = std::move(why);
  }
  // "cpu", or the device's name; with the reason where the CPU stands in.
  [[nodiscard]] std::string describe() const {
    std::string s = kernels->name();
    if (fallback != probes::BackendFallback::None)
      s += std::string("; the CPU backend runs the frame (") + probes::to_string(fallback) + "): " + fallback_why;
    return s;
  }
};

struct DdgiFrame {
  int width = 0, height = 0;  // 0 = update the probes only
  engine::ecs::Entity camera;
  engine::image::ImageRGB gi, direct, full;
  DdgiStageTimes times;
  DdgiFrameStats probe_stats;
  std::uint64_t frames = 0;
  // Host-device traffic since the last image (the probe updates and this
  // image; engine::gpu::GpuTraffic says how it is counted). 0 on the CPU.
  std::uint64_t gpu_submissions = 0, gpu_upload_bytes = 0, gpu_download_bytes = 0;
};

class DdgiPlugin final : public engine::app::Plugin {
 public:
  explicit DdgiPlugin(DdgiSettings settings = {}, DdgiRenderOptions options = {}) : settings_(settings), options_(options) {}
  void build(engine::app::App& app) override;
  [[nodiscard]] std::string_view name() const override { return "transgi::DdgiPlugin"; }

 private:
  DdgiSettings settings_;
  DdgiRenderOptions options_;
};

}  // namespace transgi::ddgi
