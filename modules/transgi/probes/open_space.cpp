#include "probes/open_space.h"

#include <cmath>
#include <deque>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
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

// The link segment from probe q's grid point to its neighbour n's.
std::optional<engine::rt::Ray> link_segment(const ProbeGrid& grid, int q, int n) {
  const glm::vec3 from = grid.grid_point(q);
  const glm::vec3 d = grid.grid_point(n) - from;
  const float len = glm::length(d);
  if (!(len > 0)) return std::nullopt;
  return engine::rt::Ray{from, d / len, 0.0f, len};
}

// The relocation segment from neighbour n's grid point moved by `offset`
// to probe q's grid point.
std::optional<engine::rt::Ray> relocation_segment(const ProbeGrid& grid, int n, glm::vec3 offset, int q) {
  const glm::vec3 from = grid.grid_point(n) + offset;
  const glm::vec3 d = grid.grid_point(q) - from;
  const float len = glm::length(d);
  if (!(len > 0)) return std::nullopt;
  return engine::rt::Ray{from, d / len, 0.0f, len};
}

// The answers of segments traced ahead, by key.
class AheadAnswers {
 public:
  AheadAnswers(const OpenSpaceSegments* ahead, int probes) : ahead_(ahead), probes_(probes) {
    if (!ahead_) return;
    if (ahead_->hit_t.size() != ahead_->keys.size() || ahead_->rays.size() != ahead_->keys.size())
      throw std::invalid_argument("find_open_space: segments traced ahead have " + std::to_string(ahead_->keys.size()) +
                                  " keys, " + std::to_string(ahead_->rays.size()) + " rays and " +
                                  std::to_string(ahead_->hit_t.size()) + " answers");
    for (std::size_t i = 0; i < ahead_->keys.size(); ++i) index_[pair(ahead_->keys[i].from, ahead_->keys[i].to)].push_back(i);
  }
  // The closest hit's distance of that segment (infinity: clear), or none
  // where it was not traced ahead.
  [[nodiscard]] std::optional<float> find(int from, int to, glm::vec3 offset, bool link) const {
    if (!ahead_) return std::nullopt;
    const auto it = index_.find(pair(from, to));
    if (it == index_.end()) return std::nullopt;
    for (const std::size_t i : it->second) {
      const OpenSpaceSegments::Key& k = ahead_->keys[i];
      if (k.link == link && k.offset == offset) return ahead_->hit_t[i];
    }
    return std::nullopt;
  }

 private:
  [[nodiscard]] std::uint64_t pair(int from, int to) const {
    return static_cast<std::uint64_t>(from) * static_cast<std::uint64_t>(probes_) + static_cast<std::uint64_t>(to);
  }
  const OpenSpaceSegments* ahead_;
  int probes_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> index_;
};

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
              const RelocationSettings& s, const AheadAnswers& ahead, OpenSpace& r) {
  using namespace engine;
  const glm::vec3 limit = s.max_offset * grid.spacing();
  const float margin = s.margin * grid.min_spacing(), min_margin = s.min_margin * grid.min_spacing();
  struct Candidate {
    int q, n;
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
        const std::optional<rt::Ray> ray = relocation_segment(grid, n, r.offsets[static_cast<std::size_t>(n)], q);
        if (!ray) return;
        candidates.push_back({q, n, ray->origin, target - ray->origin, ray->tmax});
        rays.push_back(*ray);
      });
    }
    // The segments traced ahead answer; the rest are traced now.
    std::vector<float> hit_t(rays.size(), std::numeric_limits<float>::infinity());
    std::vector<std::size_t> missing;
    std::vector<rt::Ray> missing_rays;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Candidate& c = candidates[i];
      if (const std::optional<float> t = ahead.find(c.n, c.q, r.offsets[static_cast<std::size_t>(c.n)], false)) {
        hit_t[i] = *t;
      } else {
        missing.push_back(i);
        missing_rays.push_back(rays[i]);
      }
    }
    if (!missing.empty()) {
      const std::vector<float> traced = hit_distances(scene, tracer, missing_rays);
      for (std::size_t j = 0; j < missing.size(); ++j) hit_t[missing[j]] = traced[j];
    }
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

OpenSpaceSegments open_space_segments(const ProbeGrid& grid, std::span<const std::uint8_t> expected_unlinked) {
  OpenSpaceSegments out;
  const int probes = grid.count();
  const auto add = [&](const OpenSpaceSegments::Key& key, const std::optional<engine::rt::Ray>& ray) {
    if (!ray) return;
    out.keys.push_back(key);
    out.rays.push_back(*ray);
  };
  for (int q = 0; q < probes; ++q) {
    const glm::ivec3 c = grid.coords(q);
    for (int k = 0; k < kForward; ++k) {
      const glm::ivec3 n = c + forward_offset(k);
      if (!inside_grid(grid, n)) continue;
      const int m = grid.index(n);
      add({q, m, glm::vec3(0.0f), true}, link_segment(grid, q, m));
    }
  }
  for (int q = 0; q < probes && q < static_cast<int>(expected_unlinked.size()); ++q) {
    if (!expected_unlinked[static_cast<std::size_t>(q)]) continue;
    grid.for_each_neighbour(q, [&](int n) {
      if (n == q) return;
      add({n, q, glm::vec3(0.0f), false}, relocation_segment(grid, n, glm::vec3(0.0f), q));
      const glm::vec3 moved = grid.offsets.empty() ? glm::vec3(0.0f) : grid.offsets[static_cast<std::size_t>(n)];
      if (moved != glm::vec3(0.0f)) add({n, q, moved, false}, relocation_segment(grid, n, moved, q));
    });
  }
  return out;
}

OpenSpace find_open_space(const engine::rt::RtScene& scene, const ProbeGrid& grid, std::span<const std::uint8_t> saw_light,
                          const RelocationSettings& relocation, engine::rt::RayBatchTracer* tracer,
                          const OpenSpaceSegments* traced_ahead) {
  using namespace engine;
  const int probes = grid.count();
  const AheadAnswers answers(traced_ahead, probes);
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
      for (int k = 0; k < kForward; ++k) {
        const glm::ivec3 n = c + forward_offset(k);
        if (!inside_grid(grid, n)) continue;
        const std::optional<rt::Ray> ray = link_segment(grid, q, grid.index(n));
        if (!ray) continue;
        const std::size_t slot = static_cast<std::size_t>(q) * kForward + static_cast<std::size_t>(k);
        candidate[slot] = *ray;
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
  // The segments traced ahead answer (a closest hit within the segment
  // blocks it); the rest are traced now.
  std::vector<std::size_t> missing;
  std::vector<rt::Ray> missing_rays;
  if (traced_ahead) {
    for (std::size_t i = 0; i < segments.size(); ++i) {
      const int q = segment_of[i] / kForward;
      const int n = grid.index(grid.coords(q) + forward_offset(segment_of[i] % kForward));
      if (const std::optional<float> t = answers.find(q, n, glm::vec3(0.0f), true)) {
        blocked[i] = std::isfinite(*t) ? 1 : 0;
      } else {
        missing.push_back(i);
        missing_rays.push_back(segments[i]);
      }
    }
  }
  const std::span<const rt::Ray> to_trace = traced_ahead ? std::span<const rt::Ray>(missing_rays) : std::span<const rt::Ray>(segments);
  std::vector<std::uint8_t> traced(to_trace.size(), 0);
  if (tracer && !to_trace.empty())
    tracer->occluded(scene, to_trace, traced);
  else
    jobs::parallel_for<std::size_t>(0, to_trace.size(), 64, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) traced[i] = scene.occluded(to_trace[i]) ? 1 : 0;
    });
  for (std::size_t j = 0; j < to_trace.size(); ++j) blocked[traced_ahead ? missing[j] : j] = traced[j];
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
  if (relocation.enabled) relocate(scene, tracer, grid, relocation, answers, r);
  for (std::uint8_t o : r.open) r.open_count += o;
  return r;
}

}  // namespace transgi::probes
