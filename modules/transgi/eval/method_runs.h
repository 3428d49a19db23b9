#pragma once
// One run of each method on a loaded scene, the way `transgi render`,
// `transgi eval` and `transgi bench-pareto` all need it: a number of probe
// frames, then the image on the last few frames, whose stage times (the
// paper's Table 4 rows) are reported as medians.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "ddgi/ddgi_plugin.h"
#include "engine/app/app.h"
#include "engine/image/image.h"
#include "runtime/probe_placement.h"
#include "runtime/transgi_plugin.h"

namespace transgi::eval {

struct LoadedScene {
  std::unique_ptr<engine::app::App> app;
  engine::ecs::Entity camera;
  std::vector<engine::ecs::Entity> entities;
};

// Loads a glTF scene into a fresh App (Embree mirror synced) and picks the
// named camera, or the first one.
LoadedScene load_scene(const std::string& path, const std::string& camera_name = {}, int threads = 0);

struct Stage {
  std::string name;
  double ms = 0;
};

struct MethodRun {
  engine::image::ImageRGB gi, direct, full;
  std::vector<Stage> stages;   // medians over the timed frames
  double frame_ms = 0;         // median per-frame total of the stages (direct light excluded)
  std::size_t probe_bytes = 0; // probe storage
  std::string probe_summary;   // a line about the probes' states
  std::size_t shaded_samples = 0, inferred_samples = 0;
  std::string backend;  // where the probe kernels ran (TransGI), with any fallback reason
  // The last frame's command buffers submitted to the device (0 on the CPU).
  std::uint64_t gpu_submissions = 0;
};

struct TransgiRunOptions {
  runtime::TransGISettings settings;
  int frames = 160;
  int timing_frames = 3;
  runtime::ProbePlacement placement{.mode = runtime::ProbeVolumeMode::Scene};
  std::vector<std::string> no_latent;  // node names whose LatentMesh is removed
  bool progress = true;
  // Backend::Vulkan on a device the caller made (TransGIPlugin's host_gpu);
  // null: the plugin makes its own.
  std::shared_ptr<engine::gpu::VulkanContext> host_gpu;
};

MethodRun run_transgi(LoadedScene& scene, const std::shared_ptr<const model::TransferModel>& model, int width, int height,
                      const TransgiRunOptions& options);

struct DdgiRunOptions {
  ddgi::DdgiSettings settings;
  ddgi::DdgiRenderOptions render;
  // RTXGI's hysteresis 0.97 with its brightness clamp needs a few hundred
  // updates to converge from black (tests/transgi/ddgi_test.cpp).
  int frames = 400;
  int timing_frames = 3;
  // Where the probes go, as for TransGI (scene_dims is the scene grid's).
  runtime::ProbePlacement placement{.mode = runtime::ProbeVolumeMode::Scene};
  bool progress = true;
  // Where the probes trace and blend and the image looks them up (the CPU by
  // default; gpu::make_ddgi_backend for a device).
  ddgi::DdgiBackend backend;
};

MethodRun run_ddgi(LoadedScene& scene, int width, int height, const DdgiRunOptions& options);

}  // namespace transgi::eval
