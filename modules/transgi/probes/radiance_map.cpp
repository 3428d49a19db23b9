#include "probes/radiance_map.h"

#include <algorithm>
#include <cmath>

#include "engine/core/cpu_isa.h"
#include "engine/math/sampling.h"
#include "engine/scene/environment.h"

namespace transgi::probes {

using engine::math::kShCount;

int MapLayout::texel_of_reference(const glm::vec3& d) const {
  const glm::vec2 uv = engine::scene::Environment::direction_to_uv(d);
  const int x = std::min(width - 1, static_cast<int>(uv.x * static_cast<float>(width)));
  const int y = std::min(height - 1, static_cast<int>(uv.y * static_cast<float>(height)));
  return y * width + x;
}

glm::vec3 MapLayout::direction_of(int t) const {
  const int x = t % width, y = t / width;
  return engine::scene::Environment::uv_to_direction(
      {(static_cast<float>(x) + 0.5f) / static_cast<float>(width), (static_cast<float>(y) + 0.5f) / static_cast<float>(height)});
}

double MapLayout::solid_angle(int t) const {
  const int y = t / width;
  const double pi = engine::math::kPi;
  return (2.0 * pi / width) * (std::cos(pi * y / height) - std::cos(pi * (y + 1.0) / height));
}

MapProjector::MapProjector(MapLayout layout, int sub) : layout_(layout), basis_integrals_(static_cast<std::size_t>(layout.texel_count())) {
  const double pi = engine::math::kPi;
  for (int t = 0; t < layout.texel_count(); ++t) {
    const int x = t % layout.width, y = t / layout.width;
    std::array<double, kShCount> acc{};
    for (int sy = 0; sy < sub; ++sy) {
      const double v0 = (y + static_cast<double>(sy) / sub) / layout.height, v1 = (y + (sy + 1.0) / sub) / layout.height;
      const double d_omega = (2.0 * pi / (static_cast<double>(layout.width) * sub)) * (std::cos(pi * v0) - std::cos(pi * v1));
      for (int sx = 0; sx < sub; ++sx) {
        const double u = (x + (sx + 0.5) / sub) / layout.width;
        const auto b = engine::math::sh_eval(engine::scene::Environment::uv_to_direction(
            {static_cast<float>(u), static_cast<float>(0.5 * (v0 + v1))}));
        for (int k = 0; k < kShCount; ++k) acc[static_cast<std::size_t>(k)] += b[static_cast<std::size_t>(k)] * d_omega;
      }
    }
    for (int k = 0; k < kShCount; ++k) basis_integrals_[static_cast<std::size_t>(t)][static_cast<std::size_t>(k)] = static_cast<float>(acc[static_cast<std::size_t>(k)]);
  }
}

namespace {
// One row of texels into float partial sums (25 SH x 3 colours), which the
// compiler vectorises for each ISA below; rows are summed in double.
ENGINE_INLINE_BODY void project_row_body(
    const glm::vec3* __restrict radiance, const std::array<float, kShCount>* __restrict basis, int n, float* __restrict row) {
  for (int i = 0; i < 3 * kShCount; ++i) row[i] = 0.0f;
  for (int x = 0; x < n; ++x) {
    const float r = radiance[x].r, g = radiance[x].g, b = radiance[x].b;
    const float* y = basis[x].data();
    for (int k = 0; k < kShCount; ++k) {
      row[k] += r * y[k];
      row[kShCount + k] += g * y[k];
      row[2 * kShCount + k] += b * y[k];
    }
  }
}
ENGINE_ISA_DISPATCH(void, project_row, (const glm::vec3* __restrict radiance, const std::array<float, kShCount>* __restrict basis, int n,
                   float* __restrict row),
                   (radiance, basis, n, row))
}  // namespace

void MapProjector::project(const glm::vec3* radiance, float* out) const {
  std::array<double, 3 * kShCount> acc{};
  alignas(64) float row[3 * kShCount];
  for (int y = 0; y < layout_.height; ++y) {
    const std::size_t t0 = static_cast<std::size_t>(y) * static_cast<std::size_t>(layout_.width);
    project_row(radiance + t0, basis_integrals_.data() + t0, layout_.width, row);
    for (int i = 0; i < 3 * kShCount; ++i) acc[static_cast<std::size_t>(i)] += row[i];
  }
  for (int i = 0; i < 3 * kShCount; ++i) out[i] = static_cast<float>(acc[static_cast<std::size_t>(i)]);
}

void apply_hanning_window(float* c, int degree) {
  for (int l = 1; l <= degree; ++l) {
    const float w = 0.5f * (1.0f + std::cos(engine::math::kPi * static_cast<float>(l) / static_cast<float>(degree + 1)));
    for (int ch = 0; ch < 3; ++ch)
      for (int m = -l; m <= l; ++m) c[ch * kShCount + engine::math::sh_index(l, m)] *= w;
  }
}

glm::vec3 evaluate_clamped(const float* c, const glm::vec3& d) {
  const auto b = engine::math::sh_eval(d);
  glm::vec3 out(0.0f);
  for (int ch = 0; ch < 3; ++ch) {
    float s = 0;
    for (int k = 0; k < kShCount; ++k) s += c[ch * kShCount + k] * b[static_cast<std::size_t>(k)];
    out[ch] = std::max(0.0f, s);
  }
  return out;
}

}  // namespace transgi::probes
