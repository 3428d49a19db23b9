#include "engine/image/metrics.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "engine/image/tonemap.h"
#include "engine/math/sampling.h"

namespace engine::image {

namespace {
// The mean luminance of the 3x3 pixels around (x, y) that lie in the image.
double box3_luminance(const ImageRGB& img, int x, int y) {
  double s = 0;
  int n = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if (qx < 0 || qy < 0 || qx >= img.width || qy >= img.height) continue;
      s += math::luminance(img.pixels[static_cast<std::size_t>(qy) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(qx)]);
      ++n;
    }
  return s / n;
}

void check_sizes(const ImageRGB& a, const ImageRGB& b) {
  if (a.width != b.width || a.height != b.height)
    throw ImageError("image sizes differ: " + std::to_string(a.width) + "x" + std::to_string(a.height) + " vs " +
                     std::to_string(b.width) + "x" + std::to_string(b.height));
  if (a.empty()) throw ImageError("cannot compare empty images");
}

double clamp01(float v) { return std::clamp(static_cast<double>(v), 0.0, 1.0); }

std::vector<double> luminance_clamped(const ImageRGB& img) {
  std::vector<double> y(img.size());
  for (std::size_t i = 0; i < y.size(); ++i) {
    const glm::vec3& p = img.pixels[i];
    y[i] = 0.2126 * clamp01(p.r) + 0.7152 * clamp01(p.g) + 0.0722 * clamp01(p.b);
  }
  return y;
}

}  // namespace

double rmse_clamped(const ImageRGB& a, const ImageRGB& b) {
  check_sizes(a, b);
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = clamp01(a.pixels[i][c]) - clamp01(b.pixels[i][c]);
      sum += d * d;
    }
  return std::sqrt(sum / (3.0 * static_cast<double>(a.size())));
}

std::vector<std::uint8_t> edge_band(const ImageRGB& guide, int radius, double contrast) {
  const int w = guide.width, h = guide.height;
  const auto at = [w](int x, int y) { return static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x); };
  // The luminance of each pixel's 3x3 box mean, so a noisy reference's
  // speckles are not edges.
  std::vector<double> y(guide.size());
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) y[at(px, py)] = box3_luminance(guide, px, py);
  std::vector<std::uint8_t> edge(guide.size(), 0), band(guide.size(), 0);
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const double a = y[at(px, py)];
      for (const auto& [qx, qy] : {std::pair{px + 1, py}, std::pair{px, py + 1}}) {
        if (qx >= w || qy >= h) continue;
        const double b = y[at(qx, qy)], d = std::abs(a - b);
        if (d > 0.01 && d > contrast * std::max(a, b)) edge[at(px, py)] = edge[at(qx, qy)] = 1;
      }
    }
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      if (!edge[at(px, py)]) continue;
      for (int qy = std::max(0, py - radius); qy <= std::min(h - 1, py + radius); ++qy)
        for (int qx = std::max(0, px - radius); qx <= std::min(w - 1, px + radius); ++qx) band[at(qx, qy)] = 1;
    }
  return band;
}

double rmse_clamped_in(const ImageRGB& a, const ImageRGB& b, const std::vector<std::uint8_t>& mask) {
  check_sizes(a, b);
  if (mask.size() != a.size()) throw ImageError("rmse_clamped_in: the mask is not the images' size");
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!mask[i]) continue;
    ++n;
    for (int c = 0; c < 3; ++c) {
      const double d = clamp01(a.pixels[i][c]) - clamp01(b.pixels[i][c]);
      sum += d * d;
    }
  }
  return n ? std::sqrt(sum / (3.0 * static_cast<double>(n))) : 0.0;
}

ColourMetrics compare_colour(const ImageRGB& a, const ImageRGB& b, const ImageRGB* surface_mask, const ImageRGB* albedo) {
  check_sizes(a, b);
  if (surface_mask) check_sizes(a, *surface_mask);
  if (albedo) check_sizes(a, *albedo);
  const int w = a.width, h = a.height;
  const auto at = [w](int x, int y) { return static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x); };
  const auto on_surfaces = [&](int x, int y) {
    if (!surface_mask) return true;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int xx = std::clamp(x + dx, 0, w - 1), yy = std::clamp(y + dy, 0, h - 1);
        const glm::vec3 m = surface_mask->pixels[at(xx, yy)];
        if (!((m.r + m.g + m.b) / 3 >= 0.99f)) return false;
      }
    return true;
  };
  double mean_b = 0;
  for (const glm::vec3& p : b.pixels) mean_b += math::luminance(p);
  mean_b /= static_cast<double>(std::max<std::size_t>(1, b.size()));
  const auto signed_detail = [&](const ImageRGB& img, int x, int y) {
    const double local = box3_luminance(img, x, y);
    return local > 0 ? (math::luminance(img.pixels[at(x, y)]) - local) / local : 0.0;
  };
  double a_with_albedo = 0, b_with_albedo = 0, b_squared = 0, albedo_squared = 0;
  ColourMetrics m;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::vec3 pa = glm::max(a.pixels[at(x, y)], glm::vec3(0.0f)), pb = glm::max(b.pixels[at(x, y)], glm::vec3(0.0f));
      if (!(math::luminance(pb) > 0.05 * mean_b) || !on_surfaces(x, y)) continue;
      const float sa = pa.r + pa.g + pa.b, sb = pb.r + pb.g + pb.b;
      const glm::vec3 ca = sa > 0 ? pa / sa : glm::vec3(1.0f / 3), cb = pb / sb;
      m.chroma_error += std::abs(ca.r - cb.r) + std::abs(ca.g - cb.g) + std::abs(ca.b - cb.b);
      const double da = signed_detail(a, x, y), db = signed_detail(b, x, y);
      m.detail_a += std::abs(da);
      m.detail_b += std::abs(db);
      if (albedo) {
        const double dl = signed_detail(*albedo, x, y);
        a_with_albedo += da * dl;
        b_with_albedo += db * dl;
        b_squared += db * db;
        albedo_squared += dl * dl;
      }
      ++m.pixels;
    }
  if (b_with_albedo != 0) m.texture_gain = a_with_albedo / b_with_albedo;
  if (b_squared > 0 && albedo_squared > 0) m.texture_correlation = b_with_albedo / std::sqrt(b_squared * albedo_squared);
  if (m.pixels) {
    m.chroma_error /= static_cast<double>(m.pixels);
    m.detail_a /= static_cast<double>(m.pixels);
    m.detail_b /= static_cast<double>(m.pixels);
  }
  return m;
}

ImageRGB box_downsample(const ImageRGB& img, int n) {
  if (n < 1) throw std::invalid_argument("box_downsample: the block size must be at least 1, got " + std::to_string(n));
  const int w = (img.width + n - 1) / n, h = (img.height + n - 1) / n;
  ImageRGB out(w, h);
  for (int by = 0; by < h; ++by)
    for (int bx = 0; bx < w; ++bx) {
      glm::dvec3 sum(0.0);
      int count = 0;
      for (int y = by * n; y < std::min(img.height, (by + 1) * n); ++y)
        for (int x = bx * n; x < std::min(img.width, (bx + 1) * n); ++x) {
          sum += glm::dvec3(img.at(x, y));
          ++count;
        }
      out.at(bx, by) = glm::vec3(sum / static_cast<double>(count));
    }
  return out;
}

double speckle_fraction(const ImageRGB& img, int threshold) {
  const Rgb8Image shown = to_srgb8(img);
  const int w = img.width, h = img.height;
  if (w <= 0 || h <= 0) return 0.0;
  std::size_t speckles = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool speckle = false;
      for (int c = 0; c < 3 && !speckle; ++c) {
        int v[9], k = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int qx = std::clamp(x + dx, 0, w - 1), qy = std::clamp(y + dy, 0, h - 1);
            v[k++] = shown.pixels[(static_cast<std::size_t>(qy) * w + qx) * 3 + c];
          }
        std::nth_element(v, v + 4, v + 9);
        const int own = shown.pixels[(static_cast<std::size_t>(y) * w + x) * 3 + c];
        speckle = std::abs(own - v[4]) > threshold;
      }
      speckles += speckle ? 1 : 0;
    }
  return static_cast<double>(speckles) / (static_cast<double>(w) * h);
}

double top_error_share(const ImageRGB& a, const ImageRGB& b, double fraction) {
  check_sizes(a, b);
  std::vector<double> err(a.size());
  double total = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    double s = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = clamp01(a.pixels[i][c]) - clamp01(b.pixels[i][c]);
      s += d * d;
    }
    err[i] = s;
    total += s;
  }
  if (total <= 0) return 0;
  const auto k = static_cast<std::size_t>(std::ceil(std::clamp(fraction, 0.0, 1.0) * static_cast<double>(err.size())));
  std::partial_sort(err.begin(), err.begin() + static_cast<std::ptrdiff_t>(k), err.end(), std::greater<>());
  double top = 0;
  for (std::size_t i = 0; i < k; ++i) top += err[i];
  return top / total;
}

double l1_clamped(const ImageRGB& a, const ImageRGB& b) {
  check_sizes(a, b);
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) sum += std::abs(clamp01(a.pixels[i][c]) - clamp01(b.pixels[i][c]));
  return sum / (3.0 * static_cast<double>(a.size()));
}

double relmse(const ImageRGB& a, const ImageRGB& b) {
  check_sizes(a, b);
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double r = b.pixels[i][c];
      const double d = static_cast<double>(a.pixels[i][c]) - r;
      sum += d * d / (r * r + kRelMseEpsilon);
    }
  return sum / (3.0 * static_cast<double>(a.size()));
}

double ssim_luminance(const ImageRGB& a, const ImageRGB& b) {
  check_sizes(a, b);
  constexpr int kWindow = 11;
  constexpr double kSigma = 1.5, kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  if (a.width < kWindow || a.height < kWindow)
    throw ImageError("SSIM needs images of at least 11x11 pixels, got " + std::to_string(a.width) + "x" +
                     std::to_string(a.height));
  double g[kWindow];
  double gsum = 0;
  for (int i = 0; i < kWindow; ++i) {
    const double x = i - kWindow / 2;
    g[i] = std::exp(-x * x / (2 * kSigma * kSigma));
    gsum += g[i];
  }
  for (double& v : g) v /= gsum;

  const std::vector<double> ya = luminance_clamped(a), yb = luminance_clamped(b);
  const int w = a.width, h = a.height;
  // Separable filtering of the five moment images, 'valid' region only.
  auto filter = [&](auto&& value) {
    const int ow = w - kWindow + 1, oh = h - kWindow + 1;
    std::vector<double> rows(static_cast<std::size_t>(ow) * h), out(static_cast<std::size_t>(ow) * oh);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < ow; ++x) {
        double s = 0;
        for (int k = 0; k < kWindow; ++k) s += g[k] * value(static_cast<std::size_t>(y) * w + x + k);
        rows[static_cast<std::size_t>(y) * ow + x] = s;
      }
    for (int y = 0; y < oh; ++y)
      for (int x = 0; x < ow; ++x) {
        double s = 0;
        for (int k = 0; k < kWindow; ++k) s += g[k] * rows[static_cast<std::size_t>(y + k) * ow + x];
        out[static_cast<std::size_t>(y) * ow + x] = s;
      }
    return out;
  };
  const auto mu_a = filter([&](std::size_t i) { return ya[i]; });
  const auto mu_b = filter([&](std::size_t i) { return yb[i]; });
  const auto aa = filter([&](std::size_t i) { return ya[i] * ya[i]; });
  const auto bb = filter([&](std::size_t i) { return yb[i] * yb[i]; });
  const auto ab = filter([&](std::size_t i) { return ya[i] * yb[i]; });
  double sum = 0;
  for (std::size_t i = 0; i < mu_a.size(); ++i) {
    const double ma = mu_a[i], mb = mu_b[i];
    const double va = aa[i] - ma * ma, vb = bb[i] - mb * mb, cov = ab[i] - ma * mb;
    sum += ((2 * ma * mb + kC1) * (2 * cov + kC2)) / ((ma * ma + mb * mb + kC1) * (va + vb + kC2));
  }
  return sum / static_cast<double>(mu_a.size());
}

ErrorMetrics compare_images(const ImageRGB& a, const ImageRGB& b) {
  double la = 0, lb = 0;
  glm::dvec3 ca(0.0), cb(0.0);
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    la += math::luminance(a.pixels[i]);
    lb += math::luminance(b.pixels[i]);
    ca += glm::dvec3(a.pixels[i]);
    cb += glm::dvec3(b.pixels[i]);
  }
  glm::dvec3 rgb(0.0);
  for (int c = 0; c < 3; ++c) rgb[c] = cb[c] > 0 ? ca[c] / cb[c] : 0.0;
  return {rmse_clamped(a, b), l1_clamped(a, b), ssim_luminance(a, b), relmse(a, b), lb > 0 ? la / lb : 0.0, rgb};
}

Rgb8Image error_heatmap(const ImageRGB& a, const ImageRGB& b, double max_error, double* used_max) {
  check_sizes(a, b);
  std::vector<double> err(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    double s = 0;
    for (int c = 0; c < 3; ++c) s += std::abs(clamp01(a.pixels[i][c]) - clamp01(b.pixels[i][c]));
    err[i] = s / 3.0;
  }
  if (max_error <= 0) {
    std::vector<double> sorted = err;
    const auto k = static_cast<std::size_t>(0.99 * static_cast<double>(sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
    max_error = std::max(sorted[k], 1e-6);
  }
  if (used_max) *used_max = max_error;
  Rgb8Image out(a.width, a.height);
  for (std::size_t i = 0; i < err.size(); ++i) {
    const double t = std::clamp(err[i] / max_error, 0.0, 1.0);
    // Black -> red -> yellow -> white, monotone in luminance.
    const double r = std::clamp(3.0 * t, 0.0, 1.0);
    const double gch = std::clamp(3.0 * t - 1.0, 0.0, 1.0);
    const double bch = std::clamp(3.0 * t - 2.0, 0.0, 1.0);
    out.pixels[i * 3 + 0] = static_cast<std::uint8_t>(std::lround(r * 255));
    out.pixels[i * 3 + 1] = static_cast<std::uint8_t>(std::lround(gch * 255));
    out.pixels[i * 3 + 2] = static_cast<std::uint8_t>(std::lround(bch * 255));
  }
  return out;
}

}  // namespace engine::image
