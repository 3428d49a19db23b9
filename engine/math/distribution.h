#pragma once
// Piecewise-constant 1D and 2D distributions (pbrt-v4 style) for importance
// sampling tabulated functions such as environment maps.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace engine::math {

class Distribution1D {
 public:
  Distribution1D() = default;
  // f must be non-negative and finite; an all-zero f becomes uniform.
  explicit Distribution1D(std::span<const float> f);

  [[nodiscard]] std::size_t size() const { return func_.size(); }
  [[nodiscard]] double integral() const { return integral_; }
  // Continuous sample in [0, 1); pdf is the density w.r.t. [0, 1).
  [[nodiscard]] float sample_continuous(float u, float* pdf, std::size_t* index) const;
  [[nodiscard]] float pdf(float x) const;
  // The tables, for kernels that sample the same distribution (cdf has
  // size() + 1 entries).
  [[nodiscard]] const std::vector<float>& func() const { return func_; }
  [[nodiscard]] const std::vector<double>& cdf() const { return cdf_; }

 private:
  std::vector<float> func_;
  std::vector<double> cdf_;
  double integral_ = 0;
  // A guide table (the cutpoint method): guide_[k] is the largest i with
  // cdf[i] <= k / G, so a sample's search starts in a bracket of about 8
  // entries instead of over the whole table (a 2048-wide environment row
  // was a dozen cache misses a sample). The same index as the full search.
  std::vector<std::uint32_t> guide_;
  [[nodiscard]] double guide_threshold(std::size_t k) const {
    return static_cast<double>(k) / static_cast<double>(guide_.size() - 1);
  }
};

class Distribution2D {
 public:
  Distribution2D() = default;
  // f is row-major, width x height, rows are v.
  Distribution2D(std::span<const float> f, int width, int height);

  // Returns (u, v) in [0,1)^2 and its density w.r.t. the unit square.
  [[nodiscard]] glm::vec2 sample(glm::vec2 u, float* pdf) const;
  [[nodiscard]] float pdf(glm::vec2 uv) const;
  [[nodiscard]] bool empty() const { return rows_.empty(); }
  [[nodiscard]] const std::vector<Distribution1D>& rows() const { return rows_; }
  [[nodiscard]] const Distribution1D& marginal() const { return marginal_; }

 private:
  std::vector<Distribution1D> rows_;
  Distribution1D marginal_;
};

// The same piecewise-constant density as Distribution2D over a width x
// height table, sampled with Walker's alias method (Vose's construction):
// a sample reads one entry instead of searching a marginal and a row (an
// environment map's tables are tens of MB, and each search a few cache
// misses). u.x picks the bin (its leftover places the sample across the
// bin), u.y decides between the bin and its alias (its rescaled leftover
// places the sample down the bin). The GPU's light sampling
// (shaders/light_sampling.glsl) reads the same entries the same way.
class AliasDistribution2D {
 public:
  // threshold: u.y below it keeps the bin, else its alias; pdf: the bin's
  // density w.r.t. the unit square, alias_pdf: the alias bin's.
  struct Entry {
    float threshold = 1.0f;
    std::uint32_t alias = 0;
    float pdf = 1.0f, alias_pdf = 1.0f;
  };

  AliasDistribution2D() = default;
  // f is row-major, width x height, rows are v; non-finite and negative
  // values count as 0, an all-zero f is uniform.
  AliasDistribution2D(std::span<const float> f, int width, int height);

  // Returns (u, v) in [0,1)^2 and its density w.r.t. the unit square; bin:
  // the bin it lies in (y * width + x), which a caller reads its value from
  // rather than find it again from (u, v): a sample can lie on the bin's
  // edge, which a round trip through a direction can put in the next bin.
  [[nodiscard]] glm::vec2 sample(glm::vec2 u, float* pdf, std::uint32_t* bin = nullptr) const;
  [[nodiscard]] float pdf(glm::vec2 uv) const;
  [[nodiscard]] bool empty() const { return entries_.empty(); }
  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] const std::vector<Entry>& entries() const { return entries_; }

 private:
  std::vector<Entry> entries_;
  int width_ = 0, height_ = 0;
};

}  // namespace engine::math
