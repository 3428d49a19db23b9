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

AliasDistribution2D::AliasDistribution2D(std::span<const float> f, int width, int height)
    : width_(std::max(0, width)), height_(std::max(0, height)) {
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  if (n == 0 || f.size() < n) {
    width_ = height_ = 0;
    return;
  }
  std::vector<double> value(n);
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float v = f[i];
    value[i] = v >= 0.0f && std::isfinite(v) ? static_cast<double>(v) : 0.0;
    sum += value[i];
  }
  entries_.assign(n, Entry{});
  if (!(sum > 0)) {  // uniform: every bin keeps itself
    for (std::size_t i = 0; i < n; ++i) entries_[i].alias = static_cast<std::uint32_t>(i);
    return;
  }
  const double mean = sum / static_cast<double>(n);
  std::vector<double> scaled(n);  // n x the bin's probability: 1 is a full bin
  std::vector<std::uint32_t> small, large;
  for (std::size_t i = 0; i < n; ++i) {
    scaled[i] = value[i] / mean;
    entries_[i].pdf = static_cast<float>(scaled[i]);
    entries_[i].alias = static_cast<std::uint32_t>(i);
    (scaled[i] < 1.0 ? small : large).push_back(static_cast<std::uint32_t>(i));
  }
  // Vose: each under-full bin is topped up from an over-full one, which
  // becomes its alias; what is left of that one goes back on a list.
  while (!small.empty() && !large.empty()) {
    const std::uint32_t s = small.back(), l = large.back();
    small.pop_back();
    large.pop_back();
    entries_[s].threshold = static_cast<float>(scaled[s]);
    entries_[s].alias = l;
    scaled[l] = (scaled[l] + scaled[s]) - 1.0;
    (scaled[l] < 1.0 ? small : large).push_back(l);
  }
  // The rest are full up to rounding: they keep themselves.
  for (const std::uint32_t i : small) entries_[i].threshold = 1.0f, entries_[i].alias = i;
  for (const std::uint32_t i : large) entries_[i].threshold = 1.0f, entries_[i].alias = i;
  for (Entry& e : entries_) e.alias_pdf = entries_[e.alias].pdf;
}

glm::vec2 AliasDistribution2D::sample(glm::vec2 u, float* pdf, std::uint32_t* bin_out) const {
  if (entries_.empty()) {
    if (pdf) *pdf = 0.0f;
    if (bin_out) *bin_out = 0;
    return {0.0f, 0.0f};
  }
  static constexpr float kBelowOne = 1.0f - 0x1p-24f;
  const auto n = static_cast<std::uint32_t>(entries_.size());
  const float scaled = u.x * static_cast<float>(n);
  const std::uint32_t i = std::min(static_cast<std::uint32_t>(std::max(scaled, 0.0f)), n - 1);
  const float leftover = scaled - static_cast<float>(i);
  const Entry& e = entries_[i];
  float down = u.y;
  std::uint32_t bin = i;
  float p = e.pdf;
  if (down < e.threshold) {
    down = down / e.threshold;
  } else {
    bin = e.alias;
    p = e.alias_pdf;
    down = (down - e.threshold) / (1.0f - e.threshold);
  }
  down = std::clamp(down, 0.0f, kBelowOne);
  // Across the bin: what u.x leaves after the bin, only a few bits for a
  // large table (u.x's spacing times n, for u.x in [1/2, 1)), filled in
  // with bits of `down`, so that samples do not sit on the bin's edge,
  // which a direction's round trip (Environment::pdf) can put in the next bin.
  const float spacing = std::min(1.0f, static_cast<float>(n) * 0x1p-24f);
  const float across = std::clamp(leftover + spacing * (down * 1024.0f - std::floor(down * 1024.0f)), 0.0f, kBelowOne);
  const auto w = static_cast<std::uint32_t>(width_);
  if (pdf) *pdf = p;
  if (bin_out) *bin_out = bin;
  // In the bin itself: a leftover just under 1 can round up onto the next
  // bin's edge, which then steps back one ulp.
  const auto in_bin = [](float at, std::uint32_t b, int size) {
    float t = std::min((static_cast<float>(b) + at) / static_cast<float>(size), kBelowOne);
    if (static_cast<std::uint32_t>(t * static_cast<float>(size)) > b) t = std::nextafter(t, 0.0f);
    return t;
  };
  return {in_bin(across, bin % w, width_), in_bin(down, bin / w, height_)};
}

float AliasDistribution2D::pdf(glm::vec2 uv) const {
  if (entries_.empty()) return 0.0f;
  const auto x = std::min(width_ - 1, static_cast<int>(std::max(0.0f, uv.x) * static_cast<float>(width_)));
  const auto y = std::min(height_ - 1, static_cast<int>(std::max(0.0f, uv.y) * static_cast<float>(height_)));
  return entries_[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)].pdf;
}

}  // namespace engine::math
