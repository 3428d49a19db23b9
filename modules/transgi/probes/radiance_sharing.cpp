#include "probes/radiance_sharing.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "engine/core/cpu_isa.h"
#include "engine/jobs/parallel_for.h"

namespace transgi::probes {

void DepthMap::reset(int count, float unit_length) {
  texels.assign(static_cast<std::size_t>(count), Texel{});
  unit = unit_length > 0 && std::isfinite(unit_length) ? unit_length : 1.0f;
  version = 0;
}

void DepthMap::stamp_version() {
  static std::atomic<std::uint64_t> last{0};
  version = last.fetch_add(1, std::memory_order_relaxed) + 1;
}

void DepthMap::set(std::size_t texel, float m, float v) {
  using engine::math::kHalfMax;
  version = 0;
  const float mu = m / unit, var = v / (unit * unit);
  texels[texel].mean = engine::math::to_half(std::isnan(mu) ? mu : std::min(mu, kHalfMax));
  texels[texel].variance = engine::math::to_half(std::clamp(std::isfinite(var) ? var : kHalfMax, 0.0f, kHalfMax));
}

namespace {

// One probe's shaded points as structure of arrays, so the geometry of a
// target-neighbour pair runs as vectors.
struct PointColumns {
  std::vector<float> x, y, z, nx, ny, nz;
  void fill(const std::vector<ShadedPoint>& pts) {
    const std::size_t n = pts.size();
    for (auto* v : {&x, &y, &z, &nx, &ny, &nz}) v->resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = pts[i].position.x, y[i] = pts[i].position.y, z[i] = pts[i].position.z;
      nx[i] = pts[i].normal.x, ny[i] = pts[i].normal.y, nz[i] = pts[i].normal.z;
    }
  }
};

// Per point of a neighbour, as seen from the target probe at `origin`: its
// distance, its texel and the cosine between its surface normal and the
// direction from the target (> 0: the target sees the surface from behind).
// The reference's arithmetic in the reference's order (this file is built
// without FMA contraction), so the texels are the same bits.
ENGINE_INLINE_BODY void point_geometry_body(
    const PointColumns& c, const glm::vec3& origin, const MapLayout& layout, float* __restrict dist_out,
    int* __restrict texel_out, float* __restrict facing_out) {
  const float ox = origin.x, oy = origin.y, oz = origin.z;
  const int n = static_cast<int>(c.x.size());
  const float* px = c.x.data();
  const float* py = c.y.data();
  const float* pz = c.z.data();
  const float* nx = c.nx.data();
  const float* ny = c.ny.data();
  const float* nz = c.nz.data();
  const int width = layout.width, height = layout.height;
  const float w = static_cast<float>(width), h = static_cast<float>(height);
  for (int i = 0; i < n; ++i) {
    const float dx = px[i] - ox, dy = py[i] - oy, dz = pz[i] - oz;
    const float dist = std::sqrt(dx * dx + dy * dy + dz * dz);
    const float unit = dist > 1e-6f ? dist : 1.0f;  // keeps unused lanes finite
    const float ux = dx / unit, uy = dy / unit, uz = dz / unit;
    const float u = fast_atan2(ux, -uz) * 0.15915494f, v = fast_acos(uy) * 0.31830989f;
    const float uw = u < 0 ? u + 1.0f : u;
    const int x = std::min(width - 1, std::max(0, static_cast<int>(uw * w)));
    const int y = std::min(height - 1, std::max(0, static_cast<int>(v * h)));
    dist_out[i] = dist;
    texel_out[i] = y * width + x;
    facing_out[i] = nx[i] * ux + ny[i] * uy + nz[i] * uz;
  }
}
ENGINE_ISA_DISPATCH(void, point_geometry, (const PointColumns& c, const glm::vec3& origin, const MapLayout& layout, float* __restrict dist_out,
                   int* __restrict texel_out, float* __restrict facing_out),
                   (c, origin, layout, dist_out, texel_out, facing_out))

// The reference's geometry: one point at a time through glm and
// MapLayout::texel_of (points at the origin keep dist only; they are skipped).
void point_geometry_reference(const std::vector<ShadedPoint>& pts, const glm::vec3& origin, const MapLayout& layout,
                              float* dist_out, int* texel_out, float* facing_out) {
  for (std::size_t i = 0; i < pts.size(); ++i) {
    glm::vec3 d = pts[i].position - origin;
    dist_out[i] = glm::length(d);
    if (!(dist_out[i] > 1e-6f)) continue;
    d /= dist_out[i];
    texel_out[i] = layout.texel_of(d);
    facing_out[i] = glm::dot(pts[i].normal, d);
  }
}

// Gathers each target's frame samples from its neighbourhood; `geometry(q,
// origin, dist, texel, facing)` fills, for each of probe q's points, its
// distance from the target at `origin`, its texel and the cosine between its
// normal and the direction from the target (> 0: seen from behind).
template <class Geometry>
SharingStats rasterize(const ProbeGrid& grid, const MapLayout& layout, const std::vector<std::vector<ShadedPoint>>& points,
                       const std::vector<const DepthMap*>& own_depth, const SharingSettings& s,
                       std::vector<FrameSamples>& out, std::span<const std::uint8_t> targets, const Geometry& geometry) {
  const int n = grid.count();
  out.resize(static_cast<std::size_t>(n));
  std::atomic<std::size_t> accepted{0}, rejected{0};
  engine::jobs::parallel_for(0, n, 8, [&](int b, int e) {
    std::size_t acc = 0, rej = 0;
    std::vector<float> dist, facing;
    std::vector<int> texel;
    for (int p = b; p < e; ++p) {
      if (!targets.empty() && !targets[static_cast<std::size_t>(p)]) continue;
      FrameSamples& fs = out[static_cast<std::size_t>(p)];
      fs.reset(layout.texel_count());
      const glm::vec3 origin = grid.position(p);
      const DepthMap* depth = own_depth.empty() ? nullptr : own_depth[static_cast<std::size_t>(p)];
      grid.for_each_neighbour(p, [&](int q) {
        const std::vector<ShadedPoint>& pts = points[static_cast<std::size_t>(q)];
        dist.resize(pts.size());
        texel.resize(pts.size());
        facing.resize(pts.size());
        geometry(q, origin, dist.data(), texel.data(), facing.data());
        for (std::size_t i = 0; i < pts.size(); ++i) {
          const ShadedPoint& pt = pts[i];
          if (!std::isfinite(pt.distance)) {
            if (q != p) continue;  // an escaped ray has no position to share
            const int t = layout.texel_of(pt.direction);
            fs.count[static_cast<std::size_t>(t)] += 1.0f;  // a zero sample: the probes hold indirect light only
            ++acc;
            continue;
          }
          if (!(dist[i] > 1e-6f)) continue;
          const auto t = static_cast<std::size_t>(texel[i]);
          if (q != p && s.mode == SharingMode::DepthGuard && s.same_side && facing[i] > 0) {
            ++rej;  // the target sees the point's surface from behind
            continue;
          }
          if (q != p && s.mode == SharingMode::DepthGuard && depth) {
            const float own = depth->mean(t);
            // No own hit in the texel (NaN): the target's rays there escaped
            // to the sky or have not arrived (a polar texel of the lat-long
            // map, a few rays a frame). Nothing says the point is visible
            // from the target, and where it is not (past a window's jamb,
            // above a table the target is under) it is a leak.
            if (!std::isfinite(own) || dist[i] > own * (1.0f + s.relative_tolerance) + s.absolute_tolerance * depth->unit +
                                                    s.spread_tolerance * std::sqrt(depth->variance(t))) {
              ++rej;
              continue;
            }
          }
          fs.sum[t] += pt.radiance;
          fs.count[t] += 1.0f;
          ++acc;
        }
      });
    }
    accepted += acc;
    rejected += rej;
  });
  return {accepted.load(), rejected.load()};
}

}  // namespace

SharingStats rasterize_shared(const ProbeGrid& grid, const MapLayout& layout,
                              const std::vector<std::vector<ShadedPoint>>& points, const std::vector<const DepthMap*>& own_depth,
                              const SharingSettings& s, std::vector<FrameSamples>& out,
                              std::span<const std::uint8_t> targets) {
  std::vector<PointColumns> columns(points.size());
  engine::jobs::parallel_for(0, static_cast<int>(points.size()), 16, [&](int b, int e) {
    for (int q = b; q < e; ++q) columns[static_cast<std::size_t>(q)].fill(points[static_cast<std::size_t>(q)]);
  });
  return rasterize(grid, layout, points, own_depth, s, out, targets,
                   [&](int q, const glm::vec3& origin, float* dist, int* texel, float* facing) {
                     point_geometry(columns[static_cast<std::size_t>(q)], origin, layout, dist, texel, facing);
                   });
}

SharingStats rasterize_shared_reference(const ProbeGrid& grid, const MapLayout& layout,
                                        const std::vector<std::vector<ShadedPoint>>& points,
                                        const std::vector<const DepthMap*>& own_depth, const SharingSettings& s,
                                        std::vector<FrameSamples>& out, std::span<const std::uint8_t> targets) {
  return rasterize(grid, layout, points, own_depth, s, out, targets,
                   [&](int q, const glm::vec3& origin, float* dist, int* texel, float* facing) {
                     point_geometry_reference(points[static_cast<std::size_t>(q)], origin, layout, dist, texel, facing);
                   });
}

}  // namespace transgi::probes
