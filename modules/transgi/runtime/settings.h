#pragma once
// Every TransGI run-time knob, in one resource. Each says what raising it
// buys and what it costs.
#include <cstdint>
#include <string>

#include "engine/render/temporal_aa.h"
#include "probes/probe_field.h"
#include "shading/realtime_gi.h"
#include "shading/transfer_renderer.h"

namespace transgi::runtime {

// Which path renders the GI image.
enum class GiPath {
  // Every pixel decoded from gbuffer_spp filtered samples, batched oneDNN
  // inference, SH light rotated per pixel: the paper's setting, used by eval.
  Quality,
  // Pixel-centre G-buffer, GI decoded at realtime.resolution_scale plus
  // edge pixels and upsampled, the fused decoder, SH rotated once per object.
  Realtime,
};

// How the direct light is rendered.
enum class DirectLight {
  // direct_spp next-event-estimation samples per pixel over every light,
  // seeded per frame: the reference's estimator, noisy at a few samples.
  Stochastic,
  // Realtime path only (the quality path uses Stochastic): the sun split
  // out of the environment and every punctual light with one shadow ray per
  // pixel; the residual sky and emissive meshes from the probes' direct SH
  // through the transfer. No seed, no noise; costs one packet shadow ray
  // per light per pixel.
  Deterministic,
};

// Where the probes' data-parallel stages run (issue 12).
enum class Backend {
  Cpu,     // the oracle, and this machine's real-time path
  // Probe rays, the real-time G-buffer's camera rays and their shadow rays
  // traced through a GPU BVH; the radiance raster, the SH projection and the
  // real-time transfer inference as Vulkan compute kernels (shaders/);
  // shading the hits, the accumulation and the probe interpolation stay on
  // the CPU for now. Without a usable device the CPU runs them and GiFrame
  // says why.
  Vulkan,
};

struct TransGISettings {
  GiPath gi_path = GiPath::Quality;
  Backend backend = Backend::Cpu;
  // Vulkan device name (substring) for Backend::Vulkan; empty = the
  // ENGINE_GPU_DEVICE variable, then a discrete GPU first, lavapipe last.
  std::string gpu_device;
  // Backend::Vulkan, real-time path: decode the transfer on the device.
  // True frees the CPU of its largest data-parallel stage, at the cost of
  // sending each network sample's inputs over the bus. Off by default
  // because that cost is measured and the gain is not: on an H100 beside 16
  // CPU cores the stage took 12.9 ms against the CPU's 7.9, the frame
  // 155-159 against 145-153 ms (docs/gpu-h100.md), when 150 floats of light
  // a sample still crossed the bus; they are now made on the device
  // (RealtimeGiSettings::device_lights), which no GPU has timed yet.
  bool device_inference = false;
  // Bumped to rebuild the GPU kernels from the shader folder as it is now
  // (hot reload; gpu::check_module_shaders first, so a broken edit keeps
  // the running kernels).
  std::uint32_t shader_generation = 0;
  shading::RealtimeGiSettings realtime;  // read when gi_path is Realtime
  // Realtime path: temporal antialiasing of the full image, the one a
  // player sees (engine/render/temporal_aa.h): jittered camera rays, each
  // pixel blended with its reprojected, matched and clamped history; the gi
  // and direct passes stay each frame's own. On in realtime_preset(). Off =
  // one sample at each pixel's centre: aliased edges and the single
  // G-buffer sample's error, at no cost.
  engine::render::TemporalAaSettings taa;
  // Probe rays, map size, sharing, accumulation, interpolation and skips
  // (see ProbeFieldSettings and the structs it holds; its `grid` is ignored:
  // each ProbeVolume gives its own).
  probes::ProbeFieldSettings probes;
  // G-buffer samples per pixel (each decoded by the network). Higher =
  // antialiased edges, at the cost of that many times the inference.
  int gbuffer_spp = 1;
  // Direct-light samples per pixel (shadow rays to punctual lights, sampled
  // area lights and environment). Higher = less direct-light noise, at the
  // cost of tracing time. 0 = GI only.
  int direct_spp = 4;
  DirectLight direct_light = DirectLight::Stochastic;
  // Both paths: near-mirror metals reflect by one ray, shaded with the
  // probes' GI and direct light at the hit, instead of asking SH-4 for a
  // mirror (shading::MirrorRay; max_roughness < 0 = off, the paper's setting).
  shading::MirrorRay mirror;
  // Quality path: contact light by short rays where the probes cannot see it
  // (shading::NearFieldRays: a cup on a sunlit table). 16 rays a sample
  // within one probe cell, filtered over 9 x 9 pixels: on the Breakfast Room
  // GI RMSE 0.103 -> 0.083 and mean GI 0.73x -> 0.82x of the path tracer's
  // (docs/results.md). rays = 0 = off, the paper's setting.
  shading::NearFieldRays near_field{.rays = 16};
  // Quality path: where each sample's transfer comes from. GroundTruth
  // integrates it per sample with `ground_truth_rays` rays (the bake's
  // estimator): the network replaced by its oracle, for error decomposition.
  shading::TransferSource transfer = shading::TransferSource::Network;
  int ground_truth_rays = 512;
  // Quality path: while the camera, geometry and lights stay still, the GI
  // image is the mean of the last `temporal_window` frames, each with its own
  // jittered G-buffer sample (engine/render/temporal_accumulation.h): a
  // still view antialiases at one sample per pixel per frame. 1 = off.
  // Higher = smoother edges and less noise, at the cost of that many frames
  // before a still view settles. 16: one cycle of the jitter pattern; on
  // Bitterli's rooms the GI pass's speckles 2.56 % -> 1.08 % and 0.98 % ->
  // 0.41 % of pixels, RMSE 0.080 -> 0.072 and 0.076 -> 0.068
  // (docs/image-quality.md). 1 = the paper's single frame.
  int temporal_window = 16;
  // The probes keep their state and trace nothing (error decomposition
  // renders several variants of one probe state; debugging).
  bool freeze_probes = false;
  std::uint64_t seed = 0;
};

// The settings a game runs with: the real-time GI path.
TransGISettings realtime_preset();
// The paper's setting, what eval measures.
TransGISettings quality_preset();

}  // namespace transgi::runtime
