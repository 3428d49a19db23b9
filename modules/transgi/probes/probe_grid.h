#pragma once
// A regular grid of probes over an axis-aligned box (8 x 8 x 8 by default),
// grid coordinates (0,0,0) at `min`, dims - 1 at `max`; each probe may be
// moved off its grid point (relocation, open_space.h) by up to half a cell.
//
// Storage is toroidal: probe data lives at index((c + scroll) mod dims), so a
// grid that moves by whole cells (camera-centred cascades, cascades.h) keeps
// every probe that stays in it where it is in memory, and only the slab that
// enters reuses the slots of the slab that left. Every per-probe array is
// indexed by storage index; coords() and grid_point() map it back to the
// world. scroll = 0 is the plain row-major layout.
#include <array>
#include <vector>

#include <glm/glm.hpp>

namespace transgi::probes {

struct ProbeGrid {
  glm::vec3 min{0.0f}, max{1.0f};
  glm::ivec3 dims{8};
  // Per probe, where relocation moved it from its grid point; empty = none
  // moved. Trilinear weights (cage) stay those of the grid points, as in RTXGI.
  std::vector<glm::vec3> offsets{};
  glm::ivec3 scroll{0};  // each component in [0, dims)

  bool operator==(const ProbeGrid&) const = default;

  // Probes at the centres of a dims partition of the box [lo, hi], so none
  // sits on the box's faces (a room's walls). Used by both probe plugins.
  static ProbeGrid centred_in(glm::vec3 lo, glm::vec3 hi, glm::ivec3 dims) {
    dims = glm::max(dims, glm::ivec3(1));
    const glm::vec3 half_cell = (hi - lo) / (2.0f * glm::vec3(dims));
    return ProbeGrid{lo + half_cell, hi - half_cell, dims};
  }

  [[nodiscard]] int count() const { return dims.x * dims.y * dims.z; }
  // Storage index of grid coordinates c (each in [0, dims)).
  [[nodiscard]] int index(glm::ivec3 c) const {
    c += scroll;
    c -= glm::ivec3(glm::greaterThanEqual(c, dims)) * dims;
    return (c.z * dims.y + c.y) * dims.x + c.x;
  }
  // Grid coordinates of storage index i.
  [[nodiscard]] glm::ivec3 coords(int i) const {
    glm::ivec3 c{i % dims.x, (i / dims.x) % dims.y, i / (dims.x * dims.y)};
    c -= scroll;
    c += glm::ivec3(glm::lessThan(c, glm::ivec3(0))) * dims;
    return c;
  }
  // Moves the box by whole cells (min and max by cells x spacing()) and the
  // storage origin with it, so storage index i holds the same world point
  // before and after wherever that point is still inside. Offsets stay with
  // their storage index: the caller resets those of the probes that entered
  // (entered_by_scroll).
  void scroll_by(glm::ivec3 cells);
  // Whether the probe at storage index i entered the grid with the last
  // scroll_by(cells): its world point was outside the grid before.
  [[nodiscard]] bool entered_by_scroll(int i, glm::ivec3 cells) const {
    const glm::ivec3 before = coords(i) + cells;
    return glm::any(glm::lessThan(before, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(before, dims));
  }
  // Distance between neighbouring probes per axis; an axis with a single
  // probe has no spacing (0) and is ignored by cage() and min_spacing().
  [[nodiscard]] glm::vec3 spacing() const { return (max - min) / glm::vec3(glm::max(dims - 1, glm::ivec3(1))); }
  // The probes' box grown by `cells` of its spacing on every face: the
  // points a field holds (ProbeFieldSettings::hold_cells).
  [[nodiscard]] glm::vec3 held_min(float cells) const { return min - cells * spacing(); }
  [[nodiscard]] glm::vec3 held_max(float cells) const { return max + cells * spacing(); }
  [[nodiscard]] float min_spacing() const;
  [[nodiscard]] glm::vec3 grid_point(int i) const { return min + glm::vec3(coords(i)) * spacing(); }
  [[nodiscard]] glm::vec3 position(int i) const {
    return offsets.empty() ? grid_point(i) : grid_point(i) + offsets[static_cast<std::size_t>(i)];
  }

  // The 8 probes around p (clamped to the grid) and their trilinear weights.
  struct Cage {
    std::array<int, 8> probes{};
    std::array<float, 8> weights{};
    std::array<glm::vec3, 8> positions{};  // position(probes[i]), without its divisions
  };
  // Per axis once, then the 8 corners combine them: it runs for every
  // interpolation (every decoded pixel, every probe ray's feedback).
  [[nodiscard]] Cage cage(const glm::vec3& p) const;
  // The plain statement, corner by corner through index(): the reference
  // cage() is tested against (identical results).
  [[nodiscard]] Cage cage_reference(const glm::vec3& p) const;

  // Probe q's 3x3x3 neighbourhood (itself included), clamped to the grid;
  // calls fn(neighbour index).
  template <class Fn>
  void for_each_neighbour(int q, Fn&& fn) const {
    const glm::ivec3 c = coords(q);
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const glm::ivec3 n = c + glm::ivec3(dx, dy, dz);
          if (glm::any(glm::lessThan(n, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(n, dims))) continue;
          fn(index(n));
        }
  }
};

}  // namespace transgi::probes
