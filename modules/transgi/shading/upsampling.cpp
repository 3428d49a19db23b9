#include "shading/upsampling.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "engine/core/cpu_isa.h"
#include "engine/jobs/parallel_for.h"
#include "shading/realtime_gi.h"

namespace transgi::shading {

namespace {

// guide: world normal (xyz), depth (w; 0 = miss). p is the pixel, q a cell.
float similarity(const glm::vec4& p, const glm::vec4& q, const detail::PlanRow& r) {
  if (!(q.w > 0)) return 0.0f;
  if (!r.edge_aware) return 1.0f;
  return guide_similarity(p, q, r.depth_tolerance, r.normal_power);
}

}  // namespace

namespace detail {

void plan_row_scalar(const PlanRow& r, UpsamplingPlan& u, int x0, int x1) {
  const std::size_t row = static_cast<std::size_t>(r.y) * static_cast<std::size_t>(u.width);
  const float ty = u.row_t[static_cast<std::size_t>(r.y)];
  for (int x = x0; x < x1; ++x) {
    const std::size_t p = row + static_cast<std::size_t>(x);
    const glm::vec4& gp = r.guide[x];
    if (!(gp.w > 0)) {
      u.kind[p] = UpsamplingPlan::kMiss;
      continue;
    }
    const float tx = u.col_t[static_cast<std::size_t>(x)];
    std::array<float, 4> w{};
    float total = 0;
    for (int k = 0; k < 4; ++k) {
      const float bilinear = ((k & 1) ? tx : 1 - tx) * ((k >> 1) ? ty : 1 - ty);
      w[static_cast<std::size_t>(k)] = bilinear * similarity(gp, u.cell_guide[u.cell(k, x, r.y)], r);
      total += w[static_cast<std::size_t>(k)];
    }
    if (total < r.min_weight) {
      u.kind[p] = UpsamplingPlan::kOwn;
      continue;
    }
    u.kind[p] = UpsamplingPlan::kUpsampled;
    for (std::size_t k = 0; k < 4; ++k) u.weight[k][p] = w[k] / total;
  }
}

}  // namespace detail

UpsamplingIsa best_upsampling_isa() {
  static const UpsamplingIsa isa = [] {
    const char* forced = std::getenv("TRANSGI_UPSAMPLING_ISA");
    if (forced && std::strcmp(forced, "scalar") == 0) return UpsamplingIsa::Scalar;
    if (engine::cpu::isa_enabled(engine::cpu::Isa::Avx512)) return UpsamplingIsa::Avx512;
    return engine::cpu::isa_enabled(engine::cpu::Isa::Avx2) ? UpsamplingIsa::Avx2 : UpsamplingIsa::Scalar;
  }();
  return isa;
}

const char* upsampling_isa_name(UpsamplingIsa isa) {
  switch (isa) {
    case UpsamplingIsa::Avx512: return "avx512";
    case UpsamplingIsa::Avx2: return "avx2";
    case UpsamplingIsa::Scalar: break;
  }
  return "scalar";
}

void plan_upsampling(const std::vector<glm::vec4>& guide, int width, int height, const RealtimeGiSettings& s, UpsamplingPlan& u,
                     UpsamplingIsa isa) {
  const float scale = std::clamp(s.resolution_scale, 1e-3f, 1.0f);
  u.width = width;
  u.height = height;
  u.grid_w = std::max(1, static_cast<int>(std::lround(static_cast<float>(width) * scale)));
  u.grid_h = std::max(1, static_cast<int>(std::lround(static_cast<float>(height) * scale)));
  u.sx = static_cast<float>(width) / static_cast<float>(u.grid_w);
  u.sy = static_cast<float>(height) / static_cast<float>(u.grid_h);
  u.cell_pixel.resize(static_cast<std::size_t>(u.grid_w) * u.grid_h);
  u.cell_guide.resize(u.cell_pixel.size());
  // By rows of cells in parallel: gathering the cells' guides misses cache
  // on every other pixel row.
  engine::jobs::parallel_for(0, u.grid_h, 16, [&](int j0, int j1) {
    for (int j = j0; j < j1; ++j)
      for (int i = 0; i < u.grid_w; ++i) {
        const int x = std::min(width - 1, static_cast<int>((static_cast<float>(i) + 0.5f) * u.sx));
        const int y = std::min(height - 1, static_cast<int>((static_cast<float>(j) + 0.5f) * u.sy));
        const std::size_t c = static_cast<std::size_t>(j) * u.grid_w + i;
        u.cell_pixel[c] = static_cast<std::size_t>(y) * width + x;
        u.cell_guide[c] = guide[u.cell_pixel[c]];
      }
  });
  // Output position in cell coordinates, cell centres at integers: the two
  // cells either side and the bilinear weight of the second.
  const auto axis = [](int n, float per_cell, int cells, std::vector<std::int32_t>& c0, std::vector<std::int32_t>& c1,
                       std::vector<float>& t) {
    c0.resize(static_cast<std::size_t>(n));
    c1.resize(static_cast<std::size_t>(n));
    t.resize(static_cast<std::size_t>(n));
    for (int x = 0; x < n; ++x) {
      const float f = (static_cast<float>(x) + 0.5f) / per_cell - 0.5f;
      const int i0 = static_cast<int>(std::floor(f));
      t[static_cast<std::size_t>(x)] = f - static_cast<float>(i0);
      c0[static_cast<std::size_t>(x)] = std::clamp(i0, 0, cells - 1);
      c1[static_cast<std::size_t>(x)] = std::clamp(i0 + 1, 0, cells - 1);
    }
  };
  axis(width, u.sx, u.grid_w, u.col0, u.col1, u.col_t);
  axis(height, u.sy, u.grid_h, u.row0, u.row1, u.row_t);

  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  u.kind.resize(n);
  for (auto& w : u.weight) w.resize(n);
  const bool vector = isa != UpsamplingIsa::Scalar && s.edge_aware;
  engine::jobs::parallel_for(0, height, 8, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const detail::PlanRow r{guide.data() + static_cast<std::size_t>(y) * width, &u, y, s.depth_tolerance, s.normal_power,
                              s.min_weight, s.edge_aware};
      const int done = !vector                         ? 0
                       : isa == UpsamplingIsa::Avx512 ? detail::plan_row_avx512(r, u)
                                                      : detail::plan_row_avx2(r, u);
      detail::plan_row_scalar(r, u, done, width);
    }
  });
}

}  // namespace transgi::shading
