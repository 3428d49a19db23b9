#include "probes/open_space.h"

#include <cmath>
#include <deque>
#include <limits>
#include <span>
#include <vector>

#include "engine/jobs/parallel_for.h"

namespace transgi::probes {

namespace {

// The 13 "forward" offsets of the 26-neighbourhood (those before the centre
// in z, y, x order): each segment is tested once.
constexpr int kForward = 13;
glm::ivec3 forward_offset(int k) { return {k % 3 - 1, k / 3 % 3 - 1, k / 9 - 1}; }

bool inside_grid(const ProbeGrid& grid, glm::ivec3 c) {
  return glm::all(glm::greaterThanEqual(c, glm::ivec3(0))) && glm::all(glm::lessThan(c, grid.dims));
}

// Moves unlinked probes towards linked neighbours (see the header). Passes
// repeat, so a probe in a corner can follow one moved out of the wall beside
// it; each pass only uses probes linked before it, so the order of the probes
// does not matter.
// Each segment's closest hit distance (infinity: clear), through the
// backend's tracer in one batch where it has one, else Embree.
std::vector<float> hit_distances(const engine::rt::RtScene& scene, engine::rt::RayBatchTracer* tracer,
                                 std::span<const engine::rt::Ray> rays) {
  using namespace engine;
  std::vector<float> t(rays.size(), std::numeric_limits<float>::infinity());
  std::vector<rt::Hit> hits(rays.size());
  std::vector<std::uint8_t> found(rays.size());
  if (tracer) {
    tracer->intersect(scene, rays, hits, found);
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (found[i]) t[i] = hits[i].t;
    return t;
  }
  jobs::parallel_for<std::size_t>(0, rays.size(), 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      rt::Hit hit;
      if (scene.intersect(rays[i], hit)) t[i] = hit.t;
    }
  });
  return t;
}

// Moves unlinked probes towards linked neighbours (see the header). Passes
// repeat, so a probe in a corner can follow one moved out of the wall beside
// it; each pass only uses probes linked before it, so the order of the probes
// does not matter, and a pass's segments are traced in one batch.
void relocate(const engine::rt::RtScene& scene, engine::rt::RayBatchTracer* tracer, const ProbeGrid& grid,
              const RelocationSettings& s, OpenSpace& r) {
  using namespace engine;
  const glm::vec3 limit = s.max_offset * grid.spacing();
  const float margin = s.margin * grid.min_spacing(), min_margin = s.min_margin * grid.min_spacing();
  struct Candidate {
    int q;
    glm::vec3 from, d;
    float len;
  };
  for (int pass = 0; pass < 3; ++pass) {
    const std::vector<std::uint8_t> linked = r.open;
    std::vector<Candidate> candidates;
    std::vector<rt::Ray> rays;
    for (int q = 0; q < grid.count(); ++q) {
      if (linked[static_cast<std::size_t>(q)]) continue;
      const glm::vec3 target = grid.grid_point(q);
      grid.for_each_neighbour(q, [&](int n) {
        if (n == q || !linked[static_cast<std::size_t>(n)]) return;
        const glm::vec3 from = grid.grid_point(n) + r.offsets[static_cast<std::size_t>(n)];
        const glm::vec3 d = target - from;
        const float len = glm::length(d);
        if (!(len > 0)) return;
        candidates.push_back({q, from, d, len});
        rays.push_back(rt::Ray{from, d / len, 0.0f, len});
      });
    }
    const std::vector<float> hit_t = hit_distances(scene, tracer, rays);
    int moved = 0;
    // Candidates come grouped by probe, in neighbour order.
    for (std::size_t i = 0; i < candidates.size();) {
      const int q = candidates[i].q;
      const glm::vec3 target = grid.grid_point(q);
      float best = std::numeric_limits<float>::infinity();
      glm::vec3 best_offset(0.0f);
      for (; i < candidates.size() && candidates[i].q == q; ++i) {
        const Candidate& c = candidates[i];
        const glm::vec3 dir = c.d / c.len;
        float t = c.len;
        if (std::isfinite(hit_t[i])) {
          // As far before the surface as `margin`, if the offset allows;
          // never closer than `min_margin`. The offset is (len - t) along dir.
          float reach = std::numeric_limits<float>::infinity();
          for (int a = 0; a < 3; ++a)
            if (std::abs(dir[a]) > 1e-6f) reach = std::min(reach, limit[a] / std::abs(dir[a]));
          t = std::max(hit_t[i] - margin, c.len - reach);
          if (t > hit_t[i] - std::min(min_margin, 0.5f * hit_t[i])) continue;
        }
        const glm::vec3 offset = c.from + c.d / c.len * t - target;
        if (glm::any(glm::greaterThan(glm::abs(offset), limit * 1.001f))) continue;
        const float size = glm::length(offset);
        if (size < best) {
          best = size;
          best_offset = offset;
        }
      }
      if (std::isfinite(best)) {
        r.offsets[static_cast<std::size_t>(q)] = best_offset;
        r.open[static_cast<std::size_t>(q)] = 1;
        ++moved;
      }
    }
    r.relocated += moved;
    if (moved == 0) break;
  }
}

}  // namespace

OpenSpace find_open_space(const engine::rt::RtScene& scene, const ProbeGrid& grid, std::span<const std::uint8_t> saw_light,
                          const RelocationSettings& relocation, engine::rt::RayBatchTracer* tracer) {
  using namespace engine;
  const int probes = grid.count();
  OpenSpace r;
  r.open.assign(static_cast<std::size_t>(probes), 0);
  r.offsets.assign(static_cast<std::size_t>(probes), glm::vec3(0.0f));
  std::deque<int> queue;
  for (int q = 0; q < probes && q < static_cast<int>(saw_light.size()); ++q)
    if (saw_light[static_cast<std::size_t>(q)] && (grid.offsets.empty() || grid.offsets[static_cast<std::size_t>(q)] == glm::vec3(0.0f))) {
      r.open[static_cast<std::size_t>(q)] = 1;
      queue.push_back(q);
    }
  r.seeds = static_cast<int>(queue.size());
  if (r.seeds == 0) {
    std::fill(r.open.begin(), r.open.end(), 1);
    r.open_count = probes;
    return r;
  }

  // links[q] bit k: the segment from q to q + forward_offset(k) is clear.
  // Segment s is (probe, k) = (segment_of[s] / kForward, % kForward).
  std::vector<std::uint16_t> links(static_cast<std::size_t>(probes), 0);
  // Every (probe, k) slot in parallel, then the segments that exist in
  // slot order (built serially, this was serial time every frame an
  // object moved).
  const std::size_t slots = static_cast<std::size_t>(probes) * kForward;
  std::vector<rt::Ray> candidate(slots);
  std::vector<std::uint8_t> exists(slots, 0);
  jobs::parallel_for(0, probes, 64, [&](int q0, int q1) {
    for (int q = q0; q < q1; ++q) {
      const glm::ivec3 c = grid.coords(q);
      const glm::vec3 from = grid.grid_point(q);
      for (int k = 0; k < kForward; ++k) {
        const glm::ivec3 n = c + forward_offset(k);
        if (!inside_grid(grid, n)) continue;
        const glm::vec3 d = grid.grid_point(grid.index(n)) - from;
        const float len = glm::length(d);
        if (!(len > 0)) continue;
        const std::size_t slot = static_cast<std::size_t>(q) * kForward + static_cast<std::size_t>(k);
        candidate[slot] = rt::Ray{from, d / len, 0.0f, len};
        exists[slot] = 1;
      }
    }
  });
  std::vector<rt::Ray> segments;
  std::vector<int> segment_of;
  segments.reserve(slots);
  segment_of.reserve(slots);
  for (std::size_t slot = 0; slot < slots; ++slot)
    if (exists[slot]) {
      segments.push_back(candidate[slot]);
      segment_of.push_back(static_cast<int>(slot));
    }
  std::vector<std::uint8_t> blocked(segments.size(), 0);
  if (tracer)
    tracer->occluded(scene, segments, blocked);
  else
    jobs::parallel_for<std::size_t>(0, segments.size(), 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) blocked[i] = scene.occluded(segments[i]) ? 1 : 0;
    });
  for (std::size_t i = 0; i < segments.size(); ++i)
    if (!blocked[i])
      links[static_cast<std::size_t>(segment_of[i] / kForward)] |= std::uint16_t(1u << (segment_of[i] % kForward));
  auto visit = [&](int q) {
    if (r.open[static_cast<std::size_t>(q)]) return;
    r.open[static_cast<std::size_t>(q)] = 1;
    queue.push_back(q);
  };
  while (!queue.empty()) {
    const int q = queue.front();
    queue.pop_front();
    const glm::ivec3 c = grid.coords(q);
    for (int k = 0; k < kForward; ++k) {
      const glm::ivec3 o = forward_offset(k);
      // Forward link of q, and q as the forward neighbour of c - o.
      const glm::ivec3 ahead = c + o, behind = c - o;
      if (inside_grid(grid, ahead) && (links[static_cast<std::size_t>(q)] >> k & 1u))
        visit(grid.index(ahead));
      if (inside_grid(grid, behind)) {
        const int p = grid.index(behind);
        if (links[static_cast<std::size_t>(p)] >> k & 1u) visit(p);
      }
    }
  }
  if (relocation.enabled) relocate(scene, tracer, grid, relocation, r);
  for (std::uint8_t o : r.open) r.open_count += o;
  return r;
}

}  // namespace transgi::probes
