#pragma once
// Which probes stand in open space, whatever the triangles' winding (shared by
// TransGI's probes and the DDGI baseline).
//
// Much real content has double-sided materials on meshes whose winding is
// mixed: a room's ceiling, or half of its walls, faces outwards. A probe ray
// that meets such a triangle from behind has met a surface, not the inside of
// a solid, so counting back-face hits (RTXGI's classification) buries the
// probes of a whole room. Connectivity does not depend on winding: a probe is
// in open space when a chain of unoccluded segments between neighbouring
// probes (26-neighbourhood) links it to a probe that saw light (a ray that
// escaped, met an emitter, or met a surface lit directly). A probe inside a
// wall, a closed box or a piece of furniture sees only surfaces that light
// never reaches, and every segment to its neighbours crosses a face, so no
// chain reaches it.
//
// Relocation (RTXGI moves probes out of geometry too, by back faces): a probe
// that no chain reaches is moved, by at most `max_offset` cells per axis,
// along a clear segment from a linked neighbour to just short of the
// surface that blocked it (`margin` cells before it), so a grid layer that
// lands inside a wall comes to stand in front of it.
#include <cstdint>
#include <span>
#include <vector>

#include "engine/rt/ray_batch_tracer.h"
#include "engine/rt/rt_scene.h"
#include "probes/probe_grid.h"

namespace transgi::probes {

struct OpenSpace {
  std::vector<std::uint8_t> open;  // per probe: 1 = linked to light (after relocation)
  std::vector<glm::vec3> offsets;  // per probe: relocation from its grid point (zero if none)
  int seeds = 0;                   // probes that saw light themselves
  int open_count = 0;
  int relocated = 0;
};

struct RelocationSettings {
  // Off = unlinked probes stay where they are (and are not used).
  bool enabled = true;
  // Largest move per axis, in cells (RTXGI keeps probes within 0.45). Higher =
  // more probes rescued from thick walls, at the cost of cages that no longer
  // surround their points.
  float max_offset = 0.45f;
  // Distance kept from the blocking surface, in cells of the smallest
  // spacing: `margin` where the offset allows, never less than `min_margin`.
  // Higher = probes clear of the shading biases near walls (DDGI's 0.1 m
  // normal and view offsets), at the cost of a probe further from the wall
  // it stands in for.
  float margin = 0.1f;
  float min_margin = 0.05f;

  bool operator==(const RelocationSettings&) const = default;
};

// Segments traced ahead of a search (find_open_space's `traced_ahead`): on a device
// they ride with the frame's probe rays instead of taking submissions of
// their own, since which segments a search traces hardly changes from one
// search to the next. Each is named by the probe it starts from, the probe it
// goes to and how it was made: a forward link segment between grid points,
// or a relocation segment from a neighbour's grid point moved by `offset`.
// The search looks up each segment it needs and traces only those missing,
// so its answer is the same with or without them.
struct OpenSpaceSegments {
  struct Key {
    int from = 0, to = 0;
    glm::vec3 offset{0.0f};
    bool link = false;
  };
  std::vector<Key> keys;
  std::vector<engine::rt::Ray> rays;
  // Per ray, the closest hit's distance, infinity where clear: the caller
  // fills it once they are traced.
  std::vector<float> hit_t;
};

// The segments a search over `grid` traces where the probes no chain reaches
// are those `expected_unlinked` flags (the last search's): every forward link
// segment, and the relocation segments towards each flagged probe from its
// neighbours' grid points and, for a neighbour that stands moved
// (grid.offsets), from where it stands.
OpenSpaceSegments open_space_segments(const ProbeGrid& grid, std::span<const std::uint8_t> expected_unlinked);

// saw_light: per probe, 1 if one of its rays escaped, met an emitter or met a
// directly lit surface. Where no probe saw light (a dark scene, nothing to
// link to), every probe counts as open: darkness is no evidence of a wall.
// Links and relocations are worked out from the grid points. A probe that
// stands off its grid point (grid.offsets) saw light from where it stands,
// which says nothing of its grid point: it is no seed, or every other
// classification would move it back into the wall and out again.
// With `tracer` (a GPU backend's) the segments are traced by it, a batch per
// step; without one, or where it declines the scene, by Embree.
// `traced_ahead`: segments already traced (open_space_segments), looked up before
// any is traced again.
OpenSpace find_open_space(const engine::rt::RtScene& scene, const ProbeGrid& grid, std::span<const std::uint8_t> saw_light,
                          const RelocationSettings& relocation = {}, engine::rt::RayBatchTracer* tracer = nullptr,
                          const OpenSpaceSegments* traced_ahead = nullptr);

}  // namespace transgi::probes
