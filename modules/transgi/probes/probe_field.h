#pragma once
// The SH light probes of one volume, updated frame by frame (paper Section 5):
//
//  1. scatter: every probe shoots M rays, a spherical Fibonacci set under a
//     new random rotation each frame; each hit is shaded with the radiance
//     leaving it towards the probe: direct light (next-event estimation over
//     the LightSet) plus indirect light from the previous frame's probes
//     (their interpolated irradiance times the diffuse albedo, as DDGI does).
//     Rays that hit an emitter or escape record zero: the probes hold
//     indirect light only.
//  2. raster: radiance sharing across each probe's 26 neighbours.
//  3. accumulate over frames (adaptive hysteresis), fill holes, project to
//     SH (optionally windowed against ringing).
#include <cstdint>
#include <vector>

#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"
#include "probes/interpolation.h"
#include "probes/probe_map.h"

namespace transgi::probes {

struct ProbeFieldSettings {
  ProbeGrid grid;
  MapLayout map;
  // Rays per probe per frame (the paper's M = 100). Higher = less noise per
  // frame, at the cost of ray-tracing and shading time.
  int rays_per_probe = 100;
  SharingSettings sharing;
  AccumulationSettings accumulation;
  InterpolationSettings interpolation;
  // Hanning window on the projected SH. On = less ringing of sharp light
  // (tests/transgi/probes_test.cpp), at the cost of blurrier, dimmer
  // lighting. Off by default: on the sample level it raised the GI error
  // (RMSE 0.0237 vs 0.0216 at 128 frames) and lost 5 % of the light
  // (docs/runtime.md).
  bool window = false;
  std::uint64_t seed = 1;
};

struct ProbeFrameStats {
  std::size_t rays = 0, hits = 0, shared_accepted = 0, shared_rejected = 0;
  double scatter_ms = 0, raster_ms = 0, project_ms = 0;
};

class ProbeField {
 public:
  explicit ProbeField(ProbeFieldSettings settings);

  ProbeFrameStats update(const engine::rt::RtScene& scene, const engine::render::LightSet& lights);

  // 75 SH coefficients of probe i, [c * 25 + k], world space.
  [[nodiscard]] const float* light_sh(int probe) const { return sh_.data() + static_cast<std::size_t>(probe) * 75; }
  // Interpolated SH light at a surface point (pruned trilinear).
  void interpolate(const glm::vec3& position, const glm::vec3& normal, float* out75) const;
  // Irradiance from the interpolated SH (clamped-cosine convolution).
  [[nodiscard]] glm::vec3 irradiance(const glm::vec3& position, const glm::vec3& normal) const;

  [[nodiscard]] const ProbeFieldSettings& settings() const { return settings_; }
  [[nodiscard]] std::uint64_t frame() const { return frame_; }
  [[nodiscard]] const std::vector<ProbeMapState>& states() const { return states_; }

 private:
  ProbeFieldSettings settings_;
  MapProjector projector_;
  std::vector<ProbeMapState> states_;
  std::vector<float> sh_;  // probes x 75
  std::vector<glm::vec3> fibonacci_;
  std::uint64_t frame_ = 0;
};

// Irradiance E(n) from radiance SH (Ramamoorthi and Hanrahan 2001).
glm::vec3 sh_irradiance(const float* radiance_sh, const glm::vec3& normal);

}  // namespace transgi::probes
