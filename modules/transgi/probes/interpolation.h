#pragma once
// Probe interpolation at a shading point (paper Section 5.3): trilinear over
// the 8 probes of the cage, pruning a probe that is on the back side of the
// surface (its direction from the point against the normal) or occluded (a
// Chebyshev test on its own hit-distance moments in the point's direction).
// When all 8 are pruned, the probes are averaged with distance and cosine
// weights instead, as the paper says.
//
// The moments are read bilinearly and the test is a ramp, not a cut (as
// DDGI reads its depth): read from the one nearest texel and cut at the
// threshold, a probe beyond a thin wall or a window's edge was kept or
// dropped texel by texel, and moldings and frames near it sparkled.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "probes/probe_grid.h"
#include "probes/probe_map.h"

namespace transgi::probes {

struct InterpolationSettings {
  // The visibility test starts this far along the normal (in units of the
  // grid spacing's smallest axis), so a surface does not shadow itself.
  // Higher = fewer false occlusions, at the cost of more leaks at thin walls.
  float normal_bias = 0.1f;
  // ... and this far towards the viewer, where the caller names one (the
  // camera), as DDGI's view bias: a point on a cornice or a muntin, a few
  // millimetres from a single-sheet wall, then lies clearly on the viewer's
  // side of it for a probe beyond it, whatever its normal. Higher = fewer
  // leaks through thin walls, at the cost of light judged a little off the
  // surface.
  float view_bias = 0.1f;
  // A probe whose Chebyshev visibility bound is below this is occluded.
  float visibility_threshold = 0.2f;
  // Above the threshold a probe's weight rises along a ramp, to full at
  // threshold + ramp, instead of all at once. Higher = smoother where probes
  // are half hidden, at the cost of less light from probes partly seen;
  // 0 = the paper's cut.
  float visibility_ramp = 0.3f;
  bool prune_back_facing = true;
  bool prune_occluded = true;

  bool operator==(const InterpolationSettings&) const = default;
};

struct InterpolationResult {
  std::array<int, 8> probes{};
  std::array<float, 8> weights{};  // sum to 1
  int pruned = 0;
  bool fallback = false;
};

// states[i] is probe i's accumulated state (its depth moments are read).
// usable[i] == 0 marks a probe that holds no light (buried in geometry or far
// from every surface): it gets no weight, in the fallback neither. Empty =
// every probe is usable. If no probe of the cage is usable, all weights are 0.
// viewer: where the point is seen from (the camera), for the view bias;
// null = none.
InterpolationResult interpolate_probes(const ProbeGrid& grid, const MapLayout& layout,
                                       const std::vector<ProbeMapState>& states, const glm::vec3& position,
                                       const glm::vec3& normal, const InterpolationSettings& settings,
                                       std::span<const std::uint8_t> usable = {}, const glm::vec3* viewer = nullptr);

// The same for many points: each batch of points' cages and corner geometry
// first, their depth texels fetched together, then the weights, so the
// depth maps' cache misses overlap instead of stalling point after point.
// out[i] is interpolate_probes(..., position[i], normal[i], ...) exactly.
void interpolate_probes_many(const ProbeGrid& grid, const MapLayout& layout, const std::vector<ProbeMapState>& states,
                             std::span<const glm::vec3> position, std::span<const glm::vec3> normal,
                             const InterpolationSettings& settings, std::span<const std::uint8_t> usable,
                             std::span<InterpolationResult> out, const glm::vec3* viewer = nullptr);

// The same, one cage corner at a time: the plain statement that
// interpolate_probes' vectorised corner geometry is tested against.
InterpolationResult interpolate_probes_reference(const ProbeGrid& grid, const MapLayout& layout,
                                                 const std::vector<ProbeMapState>& states, const glm::vec3& position,
                                                 const glm::vec3& normal, const InterpolationSettings& settings,
                                                 std::span<const std::uint8_t> usable = {}, const glm::vec3* viewer = nullptr);

// Where the visibility test puts the point: moved along the normal and
// towards the viewer (if any) by the settings' biases, in grid spacings.
glm::vec3 visibility_test_point(const ProbeGrid& grid, const glm::vec3& position, const glm::vec3& normal,
                                const InterpolationSettings& settings, const glm::vec3* viewer);

// Chebyshev upper bound on the probability that the probe sees a point at
// `distance`, from the mean and variance of its hit distance in that direction.
float chebyshev_visibility(float mean, float variance, float distance);

// What a visibility bound leaves of a probe's weight (0 = pruned).
float visibility_weight(float visibility, const InterpolationSettings& settings);

// The Chebyshev bound that a probe sees a point `distance` away in the
// direction that falls at `at` on its depth map (MapLayout::texel_position):
// from the first and second moments of the four nearest texel centres,
// bilinearly (wrapping around in u, clamped in v). Texels no ray has hit
// are left out (1 if all four are): a point lies on a surface, so the
// texels towards it hold hits unless it is on a silhouette, where the hits
// beside it say more than the escapes. Counted as open instead, they let a
// probe outside a closed room see its cornices past the roof's edge.
float filtered_visibility(const DepthMap& depth, const MapLayout& layout, glm::vec2 at, float distance);

}  // namespace transgi::probes
