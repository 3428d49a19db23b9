#include "engine/math/distribution.h"

#include <algorithm>
#include <cmath>

namespace engine::math {

Distribution1D::Distribution1D(std::span<const float> f) : func_(f.begin(), f.end()), cdf_(f.size() + 1, 0.0) {
  const std::size_t n = func_.size();
  for (auto& v : func_)
    if (!(v >= 0.0f) || !std::isfinite(v)) v = 0.0f;
  for (std::size_t i = 0; i < n; ++i) cdf_[i + 1] = cdf_[i] + static_cast<double>(func_[i]) / static_cast<double>(n);
  integral_ = cdf_[n];
  if (integral_ <= 0.0) {
    for (std::size_t i = 0; i <= n; ++i) cdf_[i] = static_cast<double>(i) / static_cast<double>(n);
  } else {
    for (std::size_t i = 0; i <= n; ++i) cdf_[i] /= integral_;
  }
  if (n == 0) return;
  // G + 1 thresholds k / G, k = 0..G, about one per 8 bins.
  const std::size_t g = std::max<std::size_t>(1, (n + 7) / 8);
  guide_.resize(g + 1);
  std::size_t i = 0;
  for (std::size_t k = 0; k <= g; ++k) {
    const double t = guide_threshold(k);
    while (i < n && cdf_[i + 1] <= t) ++i;
    guide_[k] = static_cast<std::uint32_t>(i);
  }
}

float Distribution1D::sample_continuous(float u, float* pdf, std::size_t* index) const {
  const std::size_t n = func_.size();
  if (guide_.empty()) {  // no bins: nothing to sample
    if (index) *index = 0;
    if (pdf) *pdf = 0.0f;
    return 0.0f;
  }
  // Largest i with cdf[i] <= u, searched between the guide entries of the
  // thresholds either side of u: cdf[guide_[k]] <= k / G <= u < (k + 1) / G
  // < cdf[guide_[k + 1] + 1], so the first entry past u lies in the bracket.
  const double ud = static_cast<double>(u);
  const std::size_t g = guide_.size() - 1;
  const double scaled = ud * static_cast<double>(g);
  std::size_t k = scaled >= 0.0 ? static_cast<std::size_t>(std::min(scaled, static_cast<double>(g - 1))) : 0;
  while (k > 0 && guide_threshold(k) > ud) --k;  // the product's rounding, either way
  while (k + 1 < g && guide_threshold(k + 1) <= ud) ++k;
  const std::size_t lo = guide_[k], hi = std::min<std::size_t>(static_cast<std::size_t>(guide_[k + 1]) + 2, cdf_.size());
  const auto it = std::upper_bound(cdf_.begin() + static_cast<std::ptrdiff_t>(lo), cdf_.begin() + static_cast<std::ptrdiff_t>(hi), ud);
  std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, (it - cdf_.begin()) - 1));
  i = std::min(i, n - 1);
  if (index) *index = i;
  double du = static_cast<double>(u) - cdf_[i];
  const double width = cdf_[i + 1] - cdf_[i];
  if (width > 0) du /= width;
  if (pdf) *pdf = integral_ > 0 ? static_cast<float>(func_[i] / integral_) : 1.0f;
  const double x = (static_cast<double>(i) + du) / static_cast<double>(n);
  return std::min(static_cast<float>(x), 1.0f - 0x1p-24f);
}

float Distribution1D::pdf(float x) const {
  const std::size_t n = func_.size();
  const auto i = std::min(n - 1, static_cast<std::size_t>(std::max(0.0f, x) * static_cast<float>(n)));
  return integral_ > 0 ? static_cast<float>(func_[i] / integral_) : 1.0f;
}

Distribution2D::Distribution2D(std::span<const float> f, int width, int height) {
  std::vector<float> marginal(static_cast<std::size_t>(height));
  rows_.reserve(static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    rows_.emplace_back(f.subspan(static_cast<std::size_t>(y) * width, static_cast<std::size_t>(width)));
    marginal[static_cast<std::size_t>(y)] = static_cast<float>(rows_.back().integral());
  }
  marginal_ = Distribution1D(marginal);
}

glm::vec2 Distribution2D::sample(glm::vec2 u, float* pdf) const {
  float pdf_v = 0, pdf_u = 0;
  std::size_t row = 0;
  const float v = marginal_.sample_continuous(u.y, &pdf_v, &row);
  const float x = rows_[row].sample_continuous(u.x, &pdf_u, nullptr);
  if (pdf) *pdf = pdf_u * pdf_v;
  return {x, v};
}

float Distribution2D::pdf(glm::vec2 uv) const {
  const std::size_t h = rows_.size();
  const auto row = std::min(h - 1, static_cast<std::size_t>(std::max(0.0f, uv.y) * static_cast<float>(h)));
  return marginal_.pdf(uv.y) * rows_[row].pdf(uv.x);
}

}  // namespace engine::math
