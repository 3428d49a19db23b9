#pragma once
// Image error metrics, defined in docs/metrics.md. A is the test image, B the
// reference. RMSE, L1 and SSIM use both images clamped to [0, 1] in linear
// space (the paper's convention); relMSE uses the unclamped HDR values.
#include <cstdint>
#include <vector>

#include "engine/image/image.h"
#include "engine/image/png.h"

namespace engine::image {

struct ErrorMetrics {
  double rmse = 0;
  double l1 = 0;
  double ssim = 0;
  double relmse = 0;
  double mean_ratio = 0;  // mean luminance of a over b's (1 = the same overall light; 0 if b is black)
  glm::dvec3 mean_ratio_rgb{0.0};  // the same per channel: a shift of hue shows as channels apart
};

inline constexpr double kRelMseEpsilon = 1e-2;

// Throws ImageError if the sizes differ or an image is smaller than the SSIM window.
ErrorMetrics compare_images(const ImageRGB& a, const ImageRGB& b);
double rmse_clamped(const ImageRGB& a, const ImageRGB& b);
// The share of the clamped squared error held by the `fraction` of pixels
// with the largest errors (0.01 = the worst 1 %): how concentrated the error is.
double top_error_share(const ImageRGB& a, const ImageRGB& b, double fraction);
double l1_clamped(const ImageRGB& a, const ImageRGB& b);
// Wang et al. 2004: 11x11 Gaussian window (sigma 1.5), K1 0.01, K2 0.03,
// L = 1, on Rec.709 luminance; mean over the 'valid' windows (no padding).
double ssim_luminance(const ImageRGB& a, const ImageRGB& b);
double relmse(const ImageRGB& a, const ImageRGB& b);

// The pixels within `radius` of an edge of `guide`: where the luminance of
// its 3x3 box mean changes between neighbours by more than `contrast` of
// the brighter one and by more than 0.01 absolute. On a direct pass, the
// band around its shadow edges (docs/metrics.md).
std::vector<std::uint8_t> edge_band(const ImageRGB& guide, int radius = 3, double contrast = 0.25);
// rmse_clamped over the pixels where mask is set; 0 where none is.
double rmse_clamped_in(const ImageRGB& a, const ImageRGB& b, const std::vector<std::uint8_t>& mask);

// Colour and texture of a test image against its reference (issue 37),
// over the pixels where the reference is lit (luminance above 5 % of its
// mean): chroma_error, the mean over them of |c(A) - c(B)|_1, c = rgb /
// (r + g + b) (a shift of hue, whatever the brightness); detail, the mean
// of |Y - (3x3 box mean of Y)| / (3x3 box mean of Y), how much the image
// varies from pixel to pixel relative to its local level (a texture's
// contrast; a reference's noise adds to it). With a surface mask (the path
// tracer's textured pass), only pixels whose 3x3 neighbourhood lies wholly
// (mask >= 0.99) on textured or coloured surfaces count: their detail is
// the texture's, not a silhouette's.
//
// With the surfaces' albedo (the path tracer's albedo pass), texture_gain:
// how much of the albedo's own pattern A carries, relative to B:
// sum d(A) d(L) / sum d(B) d(L), d the signed detail (Y - box3) / box3 and
// L the albedo. B's noise is independent of the albedo, so it averages out of
// both sums where it inflates `detail`; 1 = the texture's contrast exactly.
// texture_correlation: the correlation of d(B) with d(L), how much of B's
// detail is the texture (near 0, the gain is itself noise).
struct ColourMetrics {
  double chroma_error = 0;
  double detail_a = 0, detail_b = 0;
  double texture_gain = 0, texture_correlation = 0;
  std::size_t pixels = 0;
};
ColourMetrics compare_colour(const ImageRGB& a, const ImageRGB& b, const ImageRGB* surface_mask = nullptr,
                             const ImageRGB* albedo = nullptr);

// The image averaged over n x n pixel blocks (the last row and column of
// blocks over what they hold): compared at a scale where a path-traced
// reference's per-pixel noise has averaged out, so a metric measures the
// image rather than that noise (docs/metrics.md). n = 1 returns a copy.
ImageRGB box_downsample(const ImageRGB& img, int n);

// The fraction of pixels, as displayed (to_srgb8 at exposure 0), that lie
// more than `threshold` (8-bit levels) from the median of their 3x3
// neighbourhood in some channel: isolated bright or dark pixels, speckles
// (issue 37). A smooth image, an edge or a texture's pattern scores about 0;
// a path tracer's converged frame a few tenths of a percent. The border's
// neighbourhoods are clamped to the image.
double speckle_fraction(const ImageRGB& img, int threshold = 60);

// Per-pixel mean absolute clamped error mapped through a perceptually
// ordered colour map (black-red-yellow-white); `max_error` maps to white.
// max_error <= 0 picks the 99th percentile of the errors.
Rgb8Image error_heatmap(const ImageRGB& a, const ImageRGB& b, double max_error = 0, double* used_max = nullptr);

}  // namespace engine::image
