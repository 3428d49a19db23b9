#pragma once
// One probe's accumulated state: its radiance map over frames, its own
// hit-distance moments (for the sharing depth guard and Chebyshev
// visibility), and the SH projection shading reads.
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "probes/radiance_sharing.h"

namespace transgi::probes {

struct AccumulationSettings {
  // Weight of history per frame. Higher = smoother and less noisy, at the
  // cost of slower reaction to lighting changes.
  float hysteresis = 0.95f;
  // When this frame's mean (over the probe's sampled texels) differs from the
  // history by more than this fraction, the probe blends with
  // `fast_hysteresis` instead (adapts to lighting changes).
  float change_threshold = 0.02f;
  // ... and by more than this many standard deviations of the probe's own
  // frame-to-frame noise. Higher = fewer false alarms, at the cost of
  // reacting only to larger changes.
  float change_sigmas = 4.0f;
  float fast_hysteresis = 0.5f;
  // Cold start: the hysteresis ramps from `fast_hysteresis` to `hysteresis`
  // over this many frames, so each bounce of the multi-bounce feedback
  // propagates within a frame or two instead of ~20. Higher = smoother
  // start, at the cost of slower convergence.
  int warmup_frames = 32;
  // Dilation passes that fill never-sampled texels from sampled neighbours
  // before the map-wide mean fills the rest. Higher = better hole filling,
  // at the cost of time.
  int fill_passes = 4;

  bool operator==(const AccumulationSettings&) const = default;
};

// One texel's radiance history: binary16 in units of the probe's scale.
struct HalfRgb {
  std::uint16_t r = 0, g = 0, b = 0;
};

// The probe state is what the field keeps per probe across frames, so it is
// compact: 6 + 1 + 4 bytes a texel (radiance, flag, depth) instead of 21.
// Half precision is enough for a history that blends 5 % of a noisy frame in:
// one rounding is 2^-11 relative, far under the per-texel noise, and the
// power-of-two scale keeps any emitter strength in range.
struct ProbeMapState {
  std::vector<HalfRgb> radiance;     // history, per texel, in units of radiance_scale
  float radiance_scale = 1.0f;       // a power of two, fitted to the probe's brightest texel
  std::vector<std::uint8_t> sampled; // 0 until a texel receives its first sample (a flag: one byte)
  DepthMap depth;                    // own hit distance mean and variance (mean NaN = never hit)
  float noise_variance = 0.0f;  // running mean of (relative frame change)^2 under steady light
  int noise_frames = 0;
  int frames = 0;  // frames accumulated since reset
  float drift = 0.0f;     // exponential mean of the signed relative frame change
  int stable_frames = 0;  // (neither changed nor drifting)
  int depth_frames = 0;   // frames of own depth since reset or since the geometry last moved  // consecutive frames after the warm-up without a detected change
  // Non-zero while a device's map store (ProbeMapStore, probe_kernels.h)
  // holds this probe's radiance and sampled maps: after the device's
  // accumulation they are newer than `radiance` and `sampled` here, which
  // are stale until the store reads them back (and zeroes this). reset()
  // and release() zero it too: the host's fresh maps are then the truth,
  // sent up before the next update.
  std::uint64_t device_stamp = 0;

  // depth_unit: the length the depth is stored in units of (the grid's
  // smallest spacing).
  void reset(int texels, float depth_unit = 1.0f);
  // Frees the maps (a probe buried or far from everything holds no light,
  // so it needs none: half the probes of camera-centred cascades); reset
  // allocates them again. held() says which.
  void release();
  [[nodiscard]] bool held() const { return !radiance.empty(); }
  [[nodiscard]] glm::vec3 radiance_at(std::size_t texel) const;
  // v in [0, 2^14 * radiance_scale] is stored to 11 significant bits; more is
  // clamped to the half range (choose the scale with fitted_scale first),
  // and negative values (radiance is never negative) to 0.
  void set_radiance(std::size_t texel, const glm::vec3& v);
};

// The radiance scale for a history whose largest value (held or about to be
// stored) is `peak`: `scale` itself while the peak lies in [1/4, 2^14] of it,
// else the power of two that puts the peak in [2^11, 2^12), so the texels
// convert exactly and the bottom of the half range keeps its bits.
float fitted_scale(float scale, float peak);

// Blends this frame's samples into the history. Returns whether the probe
// detected a lighting change this frame.
bool accumulate(ProbeMapState& state, const FrameSamples& frame, const AccumulationSettings& settings);
// Updates the own-depth moments from this probe's own shaded points.
void update_own_depth(ProbeMapState& state, const MapLayout& layout, const std::vector<ShadedPoint>& own,
                      const AccumulationSettings& settings);
// update_own_depth of each *states[i] from points[batch[i]], probes in
// parallel (a backend's light stage for its batch).
void update_own_depths(std::span<const int> batch, std::span<ProbeMapState* const> states,
                       const std::vector<std::vector<ShadedPoint>>& points, const MapLayout& layout,
                       const AccumulationSettings& settings);
// The weight update_own_depth gives a texel's history this frame (the
// exponential blend's h: fast for a map's first frames, so that visibility
// follows a moved wall in a few frames). A device that updates the depth
// itself takes it from here.
float own_depth_blend(const ProbeMapState& state, const AccumulationSettings& settings);
// The radiance to project: texels never sampled are filled from sampled
// neighbours (then the map's solid-angle-weighted mean), never read as black.
std::vector<glm::vec3> filled_radiance(const ProbeMapState& state, const MapLayout& layout, int passes);

}  // namespace transgi::probes
