#pragma once
// Across-probe radiance sharing (paper Section 5.2). Every probe shoots M
// rays; each hit becomes a shaded point (position and the radiance leaving it
// towards the probe). A probe's map then accumulates the points of itself
// and its 26 neighbours, each in the texel of the direction from that probe
// to the point.
//
// On the GPU this is an atomic scatter; here each target probe gathers from
// its neighbourhood, so no two threads ever write one texel and the result
// does not depend on thread scheduling.
//
// A neighbour's point can lie behind a wall that the target probe's own rays
// hit first. With the depth guard on, such a point is rejected when its
// distance exceeds the target's own mean hit distance in that texel by more
// than the tolerance, when the target has no own hit in that texel (its rays
// there escaped, or none has arrived yet), or (same_side) when the target
// stands behind the surface the point lies on. SharingMode::PaperFaithful keeps every point
// (ablation).
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "engine/math/half.h"
#include "probes/probe_grid.h"
#include "probes/radiance_map.h"

namespace transgi::probes {

struct ShadedPoint {
  glm::vec3 position{0.0f};
  glm::vec3 radiance{0.0f};  // leaving the point towards its own probe
  glm::vec3 direction{0.0f}; // unit, from the shooting probe
  float distance = 0.0f;     // from the shooting probe; infinity when the ray escaped
  glm::vec3 normal{0.0f};    // the surface's geometric normal, on the shooting probe's side
};

enum class SharingMode { DepthGuard, PaperFaithful };

struct SharingSettings {
  SharingMode mode = SharingMode::DepthGuard;
  // A neighbour's point is rejected beyond own_depth * (1 + relative) + absolute.
  float relative_tolerance = 0.1f;
  // In units of the grid's smallest spacing (the depth maps' unit), so a
  // millimetre room is guarded as a metre one; in world units the guard let
  // every point through below about 10 cm cells.
  float absolute_tolerance = 0.05f;
  // ... plus this many standard deviations of the target's own hit distance
  // in the texel. A coarse texel spans surfaces at several depths; against
  // their mean alone the guard kept the near ones and dropped the far ones,
  // and the map took the near surfaces' light for the whole texel: on the
  // Breakfast Room, 32 x 16 maps gave 1.20x the mean GI of path-traced
  // oracle probes at the same places, 100 x 50 maps 0.97x; with 1 sigma,
  // 1.06x and 0.97x (docs/results.md). Higher = less of that bias, at the
  // cost of light through occluders whose texels also see far (2 sigma lit
  // a patch under a table in Bitterli's Living Room).
  float spread_tolerance = 1.0f;
  // A neighbour's point is shared only with probes on the side of its surface
  // that the shooting probe saw: the light leaving one side of a thin wall
  // (a single sheet, as much real content has) says nothing of the other
  // side, and the depth guard cannot tell the two sides apart. On = no light
  // through thin walls by sharing, at the cost of one dot product per point.
  bool same_side = true;
  bool operator==(const SharingSettings&) const = default;
};

// This frame's samples of one probe's map.
struct FrameSamples {
  std::vector<glm::vec3> sum;
  std::vector<float> count;
  void reset(int texels) {
    sum.assign(static_cast<std::size_t>(texels), glm::vec3(0.0f));
    count.assign(static_cast<std::size_t>(texels), 0.0f);
  }
};

// Per texel, the mean own hit distance (NaN where the probe's own rays never
// hit), which the sharing guard compares against, and its variance, for the
// Chebyshev visibility test. Both binary16 in units of `unit` (the grid's
// smallest spacing), so a scene's scale does not change their precision, and
// the variance is stored itself rather than as a mean square, which would
// cancel to nothing at half precision. 4 bytes a texel, interleaved: a
// visibility lookup reads both from one cache line.
struct DepthMap {
  struct Texel {
    std::uint16_t mean = 0x7e00;  // NaN
    std::uint16_t variance = 0;
  };
  std::vector<Texel> texels;
  float unit = 1.0f;
  // Names these texels for a device that keeps a copy (gpu::VulkanMapStore
  // sends a map up only when its version is not the one it holds): unique
  // in the process once stamped, 0 after reset() and set(), which a copy
  // never takes for its own.
  std::uint64_t version = 0;

  void reset(int count, float unit_length);
  [[nodiscard]] float mean(std::size_t texel) const { return engine::math::from_half(texels[texel].mean) * unit; }
  [[nodiscard]] float variance(std::size_t texel) const {
    return engine::math::from_half(texels[texel].variance) * unit * unit;
  }
  // Clamped into the half range (a hit 65,504 grid spacings away reads as that far).
  void set(std::size_t texel, float mean, float variance);
  // A new version for the texels as they are now (after a batch of set()).
  void stamp_version();
};

struct SharingStats {
  std::size_t accepted = 0, rejected_by_guard = 0;
};

// points[q] are probe q's shaded points this frame; own_depth[q] points to
// probe q's depth (read, not copied: the maps are large). out[p] receives
// probe p's frame samples. Escaped rays add a zero sample to their own probe only.
// targets[p] == 0 skips probe p (left empty: a budgeted frame does not update
// it); empty targets = every probe.
SharingStats rasterize_shared(const ProbeGrid& grid, const MapLayout& layout,
                              const std::vector<std::vector<ShadedPoint>>& points, const std::vector<const DepthMap*>& own_depth,
                              const SharingSettings& settings, std::vector<FrameSamples>& out,
                              std::span<const std::uint8_t> targets = {});
// The same with each point's geometry (distance, texel, facing) computed one
// point at a time: the plain statement that rasterize_shared's vectorised
// point geometry is tested against (bit-identical results).
SharingStats rasterize_shared_reference(const ProbeGrid& grid, const MapLayout& layout,
                                        const std::vector<std::vector<ShadedPoint>>& points,
                                        const std::vector<const DepthMap*>& own_depth, const SharingSettings& settings,
                                        std::vector<FrameSamples>& out, std::span<const std::uint8_t> targets = {});

}  // namespace transgi::probes
