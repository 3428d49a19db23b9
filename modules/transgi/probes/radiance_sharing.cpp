#include "probes/radiance_sharing.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "engine/jobs/parallel_for.h"

namespace transgi::probes {

void DepthMap::reset(int count, float unit_length) {
  texels.assign(static_cast<std::size_t>(count), Texel{});
  unit = unit_length > 0 && std::isfinite(unit_length) ? unit_length : 1.0f;
}

void DepthMap::set(std::size_t texel, float m, float v) {
  using engine::math::kHalfMax;
  const float mu = m / unit, var = v / (unit * unit);
  texels[texel].mean = engine::math::to_half(std::isnan(mu) ? mu : std::min(mu, kHalfMax));
  texels[texel].variance = engine::math::to_half(std::clamp(std::isfinite(var) ? var : kHalfMax, 0.0f, kHalfMax));
}

SharingStats rasterize_shared(const ProbeGrid& grid, const MapLayout& layout,
                              const std::vector<std::vector<ShadedPoint>>& points, const std::vector<const DepthMap*>& own_depth,
                              const SharingSettings& s, std::vector<FrameSamples>& out,
                              std::span<const std::uint8_t> targets) {
  const int n = grid.count();
  out.resize(static_cast<std::size_t>(n));
  std::atomic<std::size_t> accepted{0}, rejected{0};
  engine::jobs::parallel_for(0, n, 8, [&](int b, int e) {
    std::size_t acc = 0, rej = 0;
    for (int p = b; p < e; ++p) {
      if (!targets.empty() && !targets[static_cast<std::size_t>(p)]) continue;
      FrameSamples& fs = out[static_cast<std::size_t>(p)];
      fs.reset(layout.texel_count());
      const glm::vec3 origin = grid.position(p);
      const DepthMap* depth = own_depth.empty() ? nullptr : own_depth[static_cast<std::size_t>(p)];
      grid.for_each_neighbour(p, [&](int q) {
        for (const ShadedPoint& pt : points[static_cast<std::size_t>(q)]) {
          if (!std::isfinite(pt.distance)) {
            if (q != p) continue;  // an escaped ray has no position to share
            const int t = layout.texel_of(pt.direction);
            fs.count[static_cast<std::size_t>(t)] += 1.0f;  // a zero sample: the probes hold indirect light only
            ++acc;
            continue;
          }
          glm::vec3 d = pt.position - origin;
          const float dist = glm::length(d);
          if (!(dist > 1e-6f)) continue;
          d /= dist;
          const int t = layout.texel_of(d);
          if (q != p && s.mode == SharingMode::DepthGuard && s.same_side && glm::dot(pt.normal, d) > 0) {
            ++rej;  // the target sees the point's surface from behind
            continue;
          }
          if (q != p && s.mode == SharingMode::DepthGuard && depth) {
            const float own = depth->mean(static_cast<std::size_t>(t));
            if (std::isfinite(own) && dist > own * (1.0f + s.relative_tolerance) + s.absolute_tolerance) {
              ++rej;
              continue;
            }
          }
          fs.sum[static_cast<std::size_t>(t)] += pt.radiance;
          fs.count[static_cast<std::size_t>(t)] += 1.0f;
          ++acc;
        }
      });
    }
    accepted += acc;
    rejected += rej;
  });
  return {accepted.load(), rejected.load()};
}

}  // namespace transgi::probes
