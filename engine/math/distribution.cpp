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
}

float Distribution1D::sample_continuous(float u, float* pdf, std::size_t* index) const {
  const std::size_t n = func_.size();
  // Largest i with cdf[i] <= u.
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), static_cast<double>(u));
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
