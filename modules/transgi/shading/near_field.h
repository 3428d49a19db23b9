#pragma once
// Contact light that probes cannot hold. A probe's radiance map is what the
// scene looks like from the probe, up to a cell away from the surface being
// shaded. Near another object (a cup on a sunlit table, a chair by a sunlit
// floor) the surface sees that object over a far larger solid angle than any
// probe does, so probe interpolation loses the light, however dense the grid
// (docs/results.md, issue 16). A few short rays per sample find what lies
// within `reach` of the surface and put its radiance (its direct light plus
// its own probe GI, as a probe ray's hit is shaded) in place of what the
// probes' SH said for those directions. Screen-space and short-range
// world-space traces in front of a radiance cache are the same idea in
// production engines (Lumen's near field).
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/math/rng.h"
#include "engine/render/light_set.h"
#include "engine/rt/rt_scene.h"
#include "shading/gbuffer.h"

namespace transgi::shading {

struct NearFieldRays {
  // Cosine-distributed rays per sample. Higher = less noise in the contact
  // light, at the cost of that many rays (and shadow rays) per sample. 0 =
  // off: probes alone, the paper's setting.
  int rays = 0;
  // How far a ray looks, in probe cells (the smallest spacing of the grid
  // holding the sample). Higher = more of the probes' parallax replaced, at
  // the cost of longer rays and more hits to shade. Beyond about a cell the
  // probes see what the surface sees.
  float reach_cells = 1.0f;
  // The estimates are averaged over a (2 r + 1)^2 pixel window, weighted by
  // depth and normal similarity (filter_near_field). Higher = less noise, at
  // the cost of contact light smeared along a surface. 0 = unfiltered.
  int filter_radius = 4;
  // Real-time path: about this many cells trace rays a frame (0 = every
  // other cell). They form a lattice, one cell in cols_k of one row in
  // rows_k, shifted every frame, and the filter spreads their estimates over
  // the cells between, so the cost stays put as the resolution grows; neither
  // step is wider than the filter's window (2 filter_radius + 1 cells), past
  // which cells would have no estimate in reach: there the budget yields.
  // Higher = less noisy contact light, at the cost of ray time.
  int cell_budget = 0;
  // Real-time path: frames a cell's contact light is averaged over (a
  // running mean, restarted near a moved object). Higher = less noise, at
  // the cost of contact light that lags a change of light as many frames.
  int history_frames = 32;
  // Real-time path: after a cut, or a turn as sudden (a quarter of the view
  // seen anew in one frame), each new surface's contact light fades in over
  // this many frames of its mean instead of showing its first frames'
  // estimates, which mottled the whole view with the filter's blotches.
  // Higher = a calmer first moment after a cut, at the cost of contact light
  // missing in proportion for that many frames. 0 = off (surfaces seen anew
  // as the camera moves, a few percent a frame, never fade).
  int cut_fade_frames = 8;
  bool operator==(const NearFieldRays&) const = default;
};

// World SH light (75 values) at a point with a normal, as the probes give it.
using NearLightAt = std::function<void(const glm::vec3& position, const glm::vec3& normal, float* out75)>;

// The irradiance to add at `s` (world space, about its shading normal), from
// `rays` cosine-distributed directions, pi / rays x the sum of, per ray:
// - a hit on another surface within `reach`: that hit's radiance towards s,
//   minus the probes' SH radiance `light_sh` in that direction (the probes'
//   parallax replaced);
// - a hit on the sample's own entity within `own_masked_within` (the
//   distance within which its transfer's visibility masks its own object,
//   model::TransferModel::self_masked_within, in world units; 0 for samples
//   shaded without a transfer): that hit's radiance alone. The transfer
//   holds nothing from those directions, neither the probes' light nor the
//   object's own: the light a concave object (a chair's shell, a room's
//   walls and ceiling baked as one mesh) reflects onto itself.
// Zero where nothing is near. May be negative per channel: the caller
// clamps the shaded total. A null `light_sh` is interpolated with
// `light_at` at s only once a ray needs it: most rays from an open floor or
// wall meet nothing within reach, and the interpolation costs more than the ray.
glm::vec3 near_field_irradiance(const engine::rt::RtScene& scene, const engine::render::LightSet* lights,
                                const GSample& s, const float* light_sh, float reach, float own_masked_within, int rays,
                                const NearLightAt& light_at, engine::math::Pcg32& rng);

// Joint-bilateral average of per-sample values over the samples of the
// (2 radius + 1)^2 pixels around each. guide[p * spp + k] is sample k of
// pixel p (row-major, width x height): world normal (xyz) and depth (w; 0 =
// a miss). Weight max(0, 1 - (dz / 0.05 z)^2) x max(0, n . n')^8 against
// the centre sample's depth and normal, so no value crosses a silhouette or
// a crease. Misses get and give nothing (zero out). A constant over one
// surface stays that constant.
std::vector<glm::vec3> filter_near_field(std::span<const glm::vec4> guide, int width, int height, int spp,
                                         std::span<const glm::vec3> values, int radius);

// The same weights over one sample per pixel, as a horizontal then a
// vertical pass (2 (2 radius + 1) taps a pixel instead of (2 radius + 1)^2:
// the real-time frame's filter), taking only the pixels where `valid` is
// nonzero (the cells that traced rays this frame), written only where
// `wanted` is nonzero (the cells decoded this frame; elsewhere zero). Pixels
// with no valid neighbour in reach get zero. A constant over one surface
// stays that constant; a value crosses a silhouette or crease in neither pass.
// `row` is the horizontal pass's buffer, `out` the result, `estimated` per
// pixel whether any valid pixel reached it (all resized): a zero in `out`
// where none did is no estimate, not an estimate of zero.
void filter_near_field_separable(std::span<const glm::vec4> guide, int width, int height, std::span<const glm::vec3> values,
                                 std::span<const std::uint8_t> valid, std::span<const std::uint8_t> wanted, int radius,
                                 std::vector<glm::vec4>& row, std::vector<glm::vec3>& out, std::vector<std::uint8_t>& estimated);

}  // namespace transgi::shading
