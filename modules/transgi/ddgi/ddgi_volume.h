#pragma once
// The DDGI baseline (Majercik et al. 2019) with the defaults of NVIDIA's
// RTXGI SDK (DDGIVolume.h, shaders/ddgi/ProbeBlendingCS.hlsl and
// Irradiance.hlsl). It traces and shades probe rays exactly like TransGI's
// probes (probes/probe_rays.h) and uses the same grid; what differs is what
// DDGI is: per-probe octahedral irradiance and distance maps, cosine /
// power-cosine blending with hysteresis, and Chebyshev + wrap-shading
// interpolation of irradiance at a shading point.
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include "ddgi/octahedral.h"
namespace transgi::ddgi {

struct RayRecord;  // ddgi_blend.h
class DdgiKernels;
}  // namespace transgi::ddgi

#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/environment.h"
#include "probes/open_space.h"
#include "probes/probe_grid.h"

namespace transgi::ddgi {

// What an escaped probe ray records.
enum class EscapedRays {
  Zero,         // nothing: probes hold indirect light only, like TransGI's (the GI pass);
                // the environment is then sampled by next-event estimation at hits
  Environment,  // the sky's radiance, as RTXGI does; the light set must then leave the sky out
};

// RTXGI's irradiance encoding gamma: its change thresholds are in these units.
inline constexpr float kRtxgiGamma = 5.0f;

struct DdgiSettings {
  // Rays per probe per update. Higher = less noise, at the cost of tracing and blending time.
  int rays_per_probe = 256;
  // Interior texels per side (a 1-texel border is added: 8x8 and 16x16).
  // Higher = sharper directional detail, at the cost of memory and blending time.
  int irradiance_texels = 6;
  int distance_texels = 14;
  // Weight of history. Higher = less flicker, at the cost of slower reaction.
  float hysteresis = 0.97f;
  // A texel darkening by more than this (in RTXGI's gamma-5 encoding,
  // kRtxgiGamma, whatever irradiance_gamma is) lowers its hysteresis by 0.75
  // for the frame. Lower = light that goes out fades sooner, at the cost of
  // a darker mean where a texel's light is noisy (a dark update pulls it down
  // fast, a bright one slowly).
  float irradiance_threshold = 0.25f;
  // A texel changing by more than this (in the same encoding) moves only a
  // quarter of the way. RTXGI's is 0.1; off here (infinity): under daylight
  // most of a room's light comes from sunlit patches that a few rays meet
  // now and then, and clamping those rays' updates kept much of it out
  // (docs/ddgi.md). Lower = steadier under fireflies, at the cost of that bias.
  float brightness_threshold = std::numeric_limits<float>::infinity();
  // The maps hold irradiance^(1 / gamma) and blend it with the hysteresis.
  // 1 here: a running mean of the irradiance itself. RTXGI's 5 suits its
  // 10-bit maps (ours are float) and averages a perceptual encoding, whose
  // mean under noise is biased low (Jensen's inequality; docs/ddgi.md).
  float irradiance_gamma = 1.0f;
  // Sharpness of the distance filter (cosine power). Higher = crisper
  // visibility edges, at the cost of banding.
  float distance_exponent = 50.0f;
  // Shading-point offsets before the visibility test (world units, RTXGI's
  // 0.1), each at most 0.4 of the volume's smallest probe spacing
  // (DdgiVolume::biases): RTXGI's value assumes metre-sized cells, and a
  // scene a thousand times smaller would be offset a hundred of its own
  // widths. Higher = fewer self-shadowing artefacts, at the cost of light
  // leaking through thin walls.
  float normal_bias = 0.1f;
  float view_bias = 0.1f;
  // A probe whose rays hit back faces more often than this skips irradiance blending.
  float random_ray_backface_threshold = 0.1f;
  // Mark probes inside geometry inactive on the first update: they trace
  // nothing and get no weight. Inside = more than `fixed_ray_backface_threshold`
  // of the rays hit back faces of single-sided materials (RTXGI's test, off
  // by default there), or no chain of clear segments links the probe to light
  // (probes/open_space.h; winding-proof, for double-sided content). On = no
  // dark probes inside walls, at the cost of one classification pass.
  bool classification = true;
  float fixed_ray_backface_threshold = 0.25f;
  // With classification: probes that no chain links to light are moved out of
  // the geometry where a linked neighbour shows the way (probes/open_space.h).
  probes::RelocationSettings relocation;
  EscapedRays escaped = EscapedRays::Zero;
  // Not in RTXGI (0 = off, as there): over the first `warmup_frames` updates
  // the hysteresis ramps up from 0.5 and the brightness clamp is off, the
  // same cold start TransGI's probes get. From black, RTXGI's 0.97 with the
  // clamp needs thousands of updates for multi-bounce light (sample level:
  // 50 % of the reference GI after 400, 77 % after 1000). Higher = a
  // smoother start, at the cost of slower convergence.
  int warmup_frames = 0;
  // Not in RTXGI's base loop: after the warm-up, each update traces and
  // blends at most this many probes, taking every active probe in turn (0 =
  // all, every update). Warm-up and classification updates trace all.
  // Higher = faster reaction to changed light, at the cost of tracing and
  // blending time per frame.
  int probes_per_update = 0;
  // Not in RTXGI: each probe also keeps a map of the light its rays met
  // straight from emitters and the (residual) sky, blended as the
  // irradiance is, so that a pixel can take that light as direct light (as
  // TransGI's probes keep their direct SH) while the irradiance stays
  // indirect (EscapedRays::Zero). On = a GI pass that means what the path
  // tracer's means, at the cost of one more map per probe and its blend (on
  // the CPU).
  bool emitted_maps = false;
  std::uint64_t seed = 1;
  // Where several volumes hold a point (cascades, authored volumes;
  // probes/cascades.h), the band inside this grid's faces across which it
  // hands the point over to the next, in cells. Higher = smoother seams, at
  // the cost of two lookups there. 0 = a hard edge.
  float blend_cells = 0.0f;
  // How far past its outermost probes this volume holds points, in cells
  // (probes::ProbeFieldSettings::hold_cells): 0.5 for a fitted grid.
  float hold_cells = 0.0f;

  bool operator==(const DdgiSettings&) const = default;
};

struct DdgiFrameStats {
  std::size_t rays = 0;
  int inactive = 0;
  double trace_ms = 0, blend_ms = 0;
};

class DdgiVolume {
 public:
  DdgiVolume(const probes::ProbeGrid& grid, const DdgiSettings& settings);

  // One update: trace, blend irradiance and distance, update borders.
  // `sky` is what escaped rays see with EscapedRays::Environment (may be null).
  // `outer` (the next coarser cascade) lights hits outside this grid's box.
  DdgiFrameStats update(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                        const engine::scene::Environment* sky = nullptr, const DdgiVolume* outer = nullptr);

  // Runs the probe rays' tracing and the blend through `kernels` (the
  // Vulkan backend, or the CPU's: the default, and what null selects) from
  // the next update on.
  void set_kernels(std::shared_ptr<DdgiKernels> kernels);

  // Irradiance at a surface point with unit normal n, seen along view_dir
  // (from the eye towards the point), as RTXGI's DDGIGetVolumeIrradiance.
  // `lit`, if given, says whether any active probe weighed in (false: every
  // probe around is inactive, and the result is zero).
  // With `emitted` (and settings().emitted_maps), the emitted maps' value
  // there too, with the same probe weights; 0 without the maps.
  [[nodiscard]] glm::vec3 irradiance(const glm::vec3& position, const glm::vec3& normal, const glm::vec3& view_dir,
                                     bool* lit = nullptr, glm::vec3* emitted = nullptr) const;

  // The grid moved by whole cells (a cascade following the camera): probes
  // still inside keep their maps; the entered slab starts from `seed`'s
  // irradiance at each texel direction (the next coarser cascade; null =
  // black) with distances unknown, and the volume is classified again.
  // Returns how many probes entered.
  int scroll(glm::ivec3 cells, const DdgiVolume* seed);
  // The grid as placed, before relocation (probes/cascade_follow.h).
  [[nodiscard]] const probes::ProbeGrid& placement() const { return grid_; }

  [[nodiscard]] const probes::ProbeGrid& grid() const { return grid_; }
  // The normal and view biases this volume shades with: the settings',
  // capped at 0.4 of its smallest probe spacing.
  [[nodiscard]] glm::vec2 biases() const;
  // grid() with each probe where relocation moved it.
  [[nodiscard]] const probes::ProbeGrid& placed_grid() const { return placed_; }
  [[nodiscard]] const DdgiSettings& settings() const { return settings_; }
  [[nodiscard]] const OctahedralMap<glm::vec3>& irradiance_map(int probe) const { return irradiance_[static_cast<std::size_t>(probe)]; }
  [[nodiscard]] bool has_emitted_maps() const { return !emitted_.empty(); }
  // With emitted maps: a volume whose irradiance maps are these emitted maps
  // (linear, so gamma 1), so that a device's irradiance kernel looks them up
  // as it looks up any volume: the same weights, the same sums as
  // irradiance()'s `emitted`. Made when first asked after each update (the
  // CPU backend never asks: it reads the maps themselves); throws
  // std::logic_error without emitted maps.
  [[nodiscard]] const DdgiVolume& emitted_view() const;
  [[nodiscard]] const OctahedralMap<glm::vec2>& distance_map(int probe) const { return distance_[static_cast<std::size_t>(probe)]; }
  [[nodiscard]] bool active(int probe) const { return active_[static_cast<std::size_t>(probe)] != 0; }
  [[nodiscard]] std::uint64_t frame() const { return frame_; }
  [[nodiscard]] std::size_t memory_bytes() const;

 private:
  // The active probes this update traces: all of them, or this turn's share
  // of settings().probes_per_update.
  std::vector<int> probes_to_trace(bool all);
  // update()'s stages: trace, classify (the first update), blend.
  struct UpdateRays {
    std::vector<std::vector<RayRecord>> records, emitted;  // per probe (empty: not traced)
    std::vector<std::uint8_t> saw_light;                   // per probe
    std::size_t rays = 0;
  };
  UpdateRays trace(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                   const engine::scene::Environment* sky, const DdgiVolume* outer, bool all);
  void classify(const engine::rt::RtScene& scene, UpdateRays& u);
  void blend(UpdateRays& u, float hysteresis, bool warming);

  std::shared_ptr<DdgiKernels> kernels_;
  probes::ProbeGrid grid_;
  probes::ProbeGrid placed_;
  DdgiSettings settings_;
  std::vector<glm::vec3> directions_;  // unrotated spherical Fibonacci set
  std::vector<OctahedralMap<glm::vec3>> irradiance_;  // gamma-encoded E / (2 pi)
  std::vector<OctahedralMap<glm::vec2>> distance_;    // mean distance, mean squared distance
  std::vector<OctahedralMap<glm::vec3>> emitted_;     // linear E / (2 pi) of emitted light (emitted_maps; else empty)
  std::vector<std::uint8_t> active_;
  bool classified_ = false;
  std::uint64_t frame_ = 0;
  std::uint64_t budget_turn_ = 0;  // updates made under probes_per_update: whose turn it is
  mutable std::shared_ptr<const DdgiVolume> emitted_view_;
  mutable std::uint64_t emitted_view_frame_ = 0;
  void make_emitted_view() const;
};

}  // namespace transgi::ddgi
