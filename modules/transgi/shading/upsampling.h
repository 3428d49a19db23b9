#pragma once
// Joint bilateral upsampling of the real-time GI (issue 10, item 4): GI is
// decoded on a grid of cells at a fraction of the output resolution, and each
// output pixel takes its four nearest cells, weighted bilinearly times depth
// and normal similarity to the pixel. A pixel whose cells are all unlike it
// (a silhouette, a thin object) is decoded on its own instead.
//
// plan_upsampling decides, per pixel, which of those it is and its four
// weights. It runs once a frame over every output pixel, so it has vector
// kernels (AVX-512, 16 pixels at once; AVX2, 8) beside the scalar reference;
// they give bit-identical plans (tested), and the scalar one is the definition.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace transgi::shading {

struct RealtimeGiSettings;

// How alike guide q is to guide p (world normal xyz, depth w; w = 0 is a
// miss, alike to nothing): max(0, 1 - (dz / (depth_tolerance z))^2) x
// max(0, n . n')^normal_power. The upsampling's weights, and the near
// field's filter (near_field.h).
inline float guide_similarity(const glm::vec4& p, const glm::vec4& q, float depth_tolerance, int normal_power) {
  if (!(q.w > 0)) return 0.0f;
  const float dz = (q.w - p.w) / (depth_tolerance * std::max(p.w, 1e-6f));
  const float depth = std::max(0.0f, 1.0f - dz * dz);  // zero beyond the tolerance: silhouettes cut hard
  float n = std::max(0.0f, p.x * q.x + p.y * q.y + p.z * q.z), normal = 1.0f;
  for (int e = normal_power; e > 0; e >>= 1, n *= n)  // n^power by squaring
    if (e & 1) normal *= n;
  return depth * normal;
}

struct UpsamplingPlan {
  int width = 0, height = 0;   // output pixels
  int grid_w = 0, grid_h = 0;  // cells
  float sx = 1, sy = 1;        // output pixels per cell
  std::vector<std::size_t> cell_pixel;  // per cell: the output pixel it decodes
  std::vector<glm::vec4> cell_guide;    // per cell: that pixel's guide (normal, depth; w = 0 for a miss)
  // The taps of output column x are grid columns col0[x] and col1[x]
  // (clamped to the grid), the second weighing col_t[x] bilinearly; rows
  // likewise. Tap k of a pixel is column (k & 1 ? col1 : col0), row
  // (k >> 1 ? row1 : row0).
  std::vector<std::int32_t> col0, col1, row0, row1;
  std::vector<float> col_t, row_t;
  enum : std::uint8_t { kUpsampled = 0, kOwn = 1, kMiss = 2 };
  std::vector<std::uint8_t> kind;  // per pixel
  // Per pixel and tap k: the normalised weight, where kind == kUpsampled
  // (elsewhere unspecified). One plane per tap, so the vector kernel stores
  // whole vectors.
  std::array<std::vector<float>, 4> weight;

  [[nodiscard]] std::size_t cell(int k, int x, int y) const {
    const std::size_t row = static_cast<std::size_t>((k >> 1) ? row1[static_cast<std::size_t>(y)] : row0[static_cast<std::size_t>(y)]);
    return row * static_cast<std::size_t>(grid_w) +
           static_cast<std::size_t>((k & 1) ? col1[static_cast<std::size_t>(x)] : col0[static_cast<std::size_t>(x)]);
  }
};

enum class UpsamplingIsa { Scalar, Avx2, Avx512 };
// The fastest kernel the effective ISA allows (TRANSGI_MAX_ISA caps it;
// TRANSGI_UPSAMPLING_ISA=scalar forces the reference).
UpsamplingIsa best_upsampling_isa();
const char* upsampling_isa_name(UpsamplingIsa isa);

// guide: per output pixel, world normal (xyz) and depth (w; 0 = miss), row-major.
void plan_upsampling(const std::vector<glm::vec4>& guide, int width, int height, const RealtimeGiSettings& s, UpsamplingPlan& u,
                     UpsamplingIsa isa = best_upsampling_isa());

namespace detail {
// What one row's kernel reads.
struct PlanRow {
  const glm::vec4* guide;  // the row's first pixel
  const UpsamplingPlan* plan;
  int y;
  float depth_tolerance;
  int normal_power;
  float min_weight;
  bool edge_aware;
};
// Pixels [x0, x1) of the row, the reference.
void plan_row_scalar(const PlanRow& r, UpsamplingPlan& u, int x0, int x1);
// Pixels from 0 in whole vectors of 16 (edge-aware settings only); returns
// where it stopped, for the scalar kernel to finish the row.
int plan_row_avx512(const PlanRow& r, UpsamplingPlan& u);
// The same in vectors of 8, for CPUs with AVX2 and no AVX-512.
int plan_row_avx2(const PlanRow& r, UpsamplingPlan& u);
}  // namespace detail

}  // namespace transgi::shading
