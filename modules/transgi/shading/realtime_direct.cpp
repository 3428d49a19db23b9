#include "shading/realtime_direct.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/jobs/parallel_for.h"
#include "engine/render/camera_hit_tracer.h"
#include "engine/math/sampling.h"

namespace transgi::shading {

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr float kNotReceiver = std::numeric_limits<float>::quiet_NaN();
}  // namespace

glm::vec2 disk_pattern(int x, int y) {
  // Index in the 8x8 block in bit-reversed order, so neighbouring pixels
  // take far-apart points of the sequence.
  const unsigned i = static_cast<unsigned>((x & 7) | ((y & 7) << 3));
  unsigned r = 0;
  for (int b = 0; b < 6; ++b) r |= ((i >> b) & 1u) << (5 - b);
  return engine::math::r2_point(r);
}

std::array<engine::render::LightSample, kDiskPatternCells> directional_pattern(const engine::render::LightSet& lights,
                                                                               std::size_t light) {
  std::array<engine::render::LightSample, kDiskPatternCells> out;
  for (int i = 0; i < kDiskPatternCells; ++i)
    lights.sample_punctual(light, glm::vec3(0.0f), disk_pattern(i & 7, i >> 3), out[static_cast<std::size_t>(i)]);
  return out;
}

glm::ivec2 disk_pattern_shift(int phase) {
  // A 4x4 grid of even offsets, visited in bit-reversed order.
  const unsigned k = static_cast<unsigned>(((phase % kDiskPatternPhases) + kDiskPatternPhases) % kDiskPatternPhases);
  const unsigned r = ((k & 1u) << 3) | ((k & 2u) << 1) | ((k & 4u) >> 1) | ((k & 8u) >> 3);
  return {2 * static_cast<int>(r & 3u), 2 * static_cast<int>(r >> 2)};
}

DirectTileShader::DirectTileShader(const engine::rt::RtScene& scene, const engine::render::LightSet& lights,
                                   const engine::render::CameraRays& camera, int width, int height,
                                   engine::image::ImageRGB recycled, int pattern_phase)
    : scene_(scene),
      lights_(lights),
      camera_(camera),
      out_(recycled.width == width && recycled.height == height ? std::move(recycled) : engine::image::ImageRGB(width, height)),
      n_lights_(lights.punctual_count()),
      pattern_shift_(disk_pattern_shift(pattern_phase)),
      rays_per_tile_(static_cast<std::size_t>((width + 3) / 4) * static_cast<std::size_t>((height + 3) / 4), 0) {
  using namespace engine;
  // A directional light's sample does not depend on the point: its 64
  // pattern directions are computed once per frame, not per pixel.
  directional_.resize(n_lights_);
  is_directional_.assign(n_lights_, 0);
  soft_of_.assign(n_lights_, -1);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  for (std::size_t l = 0; l < n_lights_; ++l) {
    const render::PunctualInstance& light = lights.punctual_lights()[l];
    if (light.light.type != scene::PunctualLight::Type::Directional) continue;
    is_directional_[l] = 1;
    directional_[l] = directional_pattern(lights, l);
    if (!(light.angular_radius > 0.0f)) continue;
    SoftLight soft;
    soft.light = l;
    soft.tan_radius = std::tan(std::min(light.angular_radius, 1.5f));
    soft.centre = directional_[l][0];
    soft.centre.direction = -light.direction;
    // Not cleared here: each tile writes its own pixels (shade_tile).
    soft.blocker = std::make_unique_for_overwrite<float[]>(pixels);
    soft_of_[l] = static_cast<int>(soft_.size());
    soft_.push_back(std::move(soft));
  }
}

void DirectTileShader::shade_tile(const GBuffer& g, int tx, int ty, Scratch& scratch) {
  using namespace engine;
  rt::Ray* rays = scratch.rays;
  rt::Hit* hits = scratch.hits;
  bool* found = scratch.found;
  float* distance = scratch.distance;
  std::size_t* pixel = scratch.pixel;
  const GSample** samples = scratch.samples;
  std::array<glm::vec3, 2>* local = scratch.local;
  glm::vec3* light = scratch.light;
  std::size_t traced = 0;
  const scene::Environment* background = lights_.background();
  const std::size_t tile = static_cast<std::size_t>(ty / 4) * static_cast<std::size_t>((g.width + 3) / 4) + static_cast<std::size_t>(tx / 4);
  const bool collecting = batch_.collect != nullptr;
  std::size_t answer = batch_.distances ? (*batch_.first)[tile] : 0;
  // Emission and background first. Every pixel of the tile is written here
  // (the image and the soft lights' visibility are not cleared beforehand).
  for (int y = ty; y < std::min(ty + 4, g.height); ++y)
    for (int x = tx; x < std::min(tx + 4, g.width); ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * g.width + x;
      const GSample& s = g.samples[p];
      if (collecting) break;
      if (s.hit)
        out_.pixels[p] = s.emission;
      else if (background)
        out_.pixels[p] = background->radiance(camera_.generate({static_cast<float>(x) + 0.5f + g.jitter.x, static_cast<float>(y) + 0.5f + g.jitter.y}).direction);
      else
        out_.pixels[p] = glm::vec3(0.0f);
      for (SoftLight& soft : soft_) soft.blocker[p] = kNotReceiver;
    }
  for (std::size_t l = 0; l < n_lights_; ++l) {
    SoftLight* soft = soft_of_[l] >= 0 ? &soft_[static_cast<std::size_t>(soft_of_[l])] : nullptr;
    int n = 0;
    for (int y = ty; y < std::min(ty + 4, g.height); ++y)
      for (int x = tx; x < std::min(tx + 4, g.width); ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * g.width + x;
        const GSample& s = g.samples[p];
        if (!s.hit) continue;
        render::LightSample ls;
        if (is_directional_[l])
          ls = directional_[l][static_cast<std::size_t>(((x + pattern_shift_.x) & 7) | (((y + pattern_shift_.y) & 7) << 3))];
        else if (!lights_.sample_punctual(l, s.position, disk_pattern(x + pattern_shift_.x, y + pattern_shift_.y), ls))
          continue;
        const math::Frame frame = math::Frame::from_normal(s.normal_world);
        const glm::vec3 wo = frame.to_local(s.wo_world);
        if (soft) {
          // The BRDF along the disk's centre; the pattern ray only says
          // whether this part of the disk is seen.
          const glm::vec3 wc = frame.to_local(soft->centre.direction);
          if (glm::dot(soft->centre.direction, s.geometric_normal) <= 0 || wo.z <= 0 || wc.z <= 0) continue;
          if (!collecting) soft->blocker[p] = 0.0f;  // blocked by the surface itself unless its ray says otherwise
          if (glm::dot(ls.direction, s.geometric_normal) <= 0) continue;
        } else {
          if (glm::dot(ls.direction, s.geometric_normal) <= 0) continue;
          const glm::vec3 wi = frame.to_local(ls.direction);
          if (wo.z <= 0 || wi.z <= 0 || ls.radiance == glm::vec3(0.0f)) continue;
          local[n] = {wo, wi};
          light[n] = ls.radiance;
        }
        // The view's answers need no ray of their own.
        if (!batch_.view) {
          const float tmax = std::isinf(ls.distance) ? kInf : ls.distance * (1.0f - 1e-4f);
          rays[n] = rt::Ray{rt::offset_ray_origin(s.position, s.geometric_normal, scene_.offset_scale()), ls.direction, 0.0f, tmax};
        }
        pixel[n] = p;
        samples[n] = &s;
        ++n;
      }
    if (n == 0) continue;
    if (collecting) {
      (*batch_.collect)[tile].insert((*batch_.collect)[tile].end(), rays, rays + n);
      continue;
    }
    if (batch_.view) {
      const std::size_t pixels = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
      std::size_t untraced = 0;
      for (int i = 0; i < n; ++i) {
        distance[i] = (*batch_.view)[l * pixels + pixel[i]];
        if (std::isnan(distance[i])) {
          distance[i] = 0.0f;
          ++untraced;
        }
      }
      if (untraced) untraced_.fetch_add(untraced, std::memory_order_relaxed);
    } else if (batch_.distances) {
      for (int i = 0; i < n; ++i) distance[i] = (*batch_.distances)[answer++];
    } else if (soft) {
      scene_.intersect16(rays, n, hits, found);
      for (int i = 0; i < n; ++i) distance[i] = found[i] ? hits[i].t : kInf;
    } else {
      bool blocked[16];
      scene_.occluded16(rays, n, blocked);
      for (int i = 0; i < n; ++i) distance[i] = blocked[i] ? 0.0f : kInf;
    }
    traced += static_cast<std::size_t>(n);
    if (soft) {
      for (int i = 0; i < n; ++i) soft->blocker[pixel[i]] = distance[i];
      continue;
    }
    // The BRDF only where the light arrives: most of a room's pixels that face
    // the sun are in shadow.
    for (int i = 0; i < n; ++i) {
      if (distance[i] < kInf) continue;
      const glm::vec3 c = material::brdf_eval(samples[i]->brdf, local[i][0], local[i][1]) * local[i][1].z * light[i];
      if (c.r > 0 || c.g > 0 || c.b > 0) out_.pixels[pixel[i]] += c;
    }
  }
  if (collecting) return;
  // The pass's boundary: an infinite emitter or light leaves no non-finite pixel.
  std::size_t bad = 0;
  for (int y = ty; y < std::min(ty + 4, g.height); ++y)
    for (int x = tx; x < std::min(tx + 4, g.width); ++x) {
      glm::vec3& v = out_.pixels[static_cast<std::size_t>(y) * g.width + x];
      if (std::isfinite(v.r) && std::isfinite(v.g) && std::isfinite(v.b)) continue;
      v = glm::vec3(0.0f);
      ++bad;
    }
  if (bad) nonfinite_.fetch_add(bad, std::memory_order_relaxed);
  rays_per_tile_[tile] = static_cast<std::uint32_t>(traced);
}

namespace {

// The blocker search (PCSS's first step), per 2x2 cell of pixels, over the
// 8x8 cells (16x16 pixels, which hold every point of the 8x8 pattern)
// around it: how many pattern rays are blocked and how many lit (a pixel
// whose window holds both is in or near a penumbra), and the blockers'
// harmonic mean distance, which leans to the nearest (a table's shadow
// inside a window's keeps the table's narrow penumbra). A ray blocked by its
// own surface (distance 0: that part of the disk is below the surface's
// horizon) counts as blocked but says nothing of the width. Window sums are
// running sums along the cell rows, then down the cell columns: O(1) a
// cell, the same whatever the thread count, and only over the bands of
// 8 pixel rows that hold both blocked and lit rays, and the bands beside
// them.
constexpr int kCell = 2;
constexpr int kWindowCells = 8;  // 16 pixels

// No member initialisers: the per-cell arrays are written cell by cell, not
// cleared first (WindowSums{} is zero).
struct WindowSums {
  std::int32_t blocked, traced, lit;
  float inverse_distance;
  void add(const WindowSums& o, int sign) {
    blocked += sign * o.blocked;
    traced += sign * o.traced;
    lit += sign * o.lit;
    inverse_distance += static_cast<float>(sign) * o.inverse_distance;
  }
};

// Per pixel: the penumbra's half-width in pixels, 1 to 8 (0: not in or near
// a penumbra, or not a receiver). A mean over a sliding window, it changes
// smoothly from pixel to pixel.
void penumbra_radius(const GBuffer& g, std::span<const float> blocker, float tan_radius, float pixel_spread,
                     std::span<std::uint8_t> radius) {
  const int w = g.width, h = g.height;
  const int cw = (w + kCell - 1) / kCell, ch = (h + kCell - 1) / kCell;
  const auto cell_at = [cw](int cx, int cy) { return static_cast<std::size_t>(cy) * static_cast<std::size_t>(cw) + static_cast<std::size_t>(cx); };
  constexpr int kBandCells = 8 / kCell;
  const int bands = (ch + kBandCells - 1) / kBandCells;
  const auto cells = std::make_unique_for_overwrite<WindowSums[]>(static_cast<std::size_t>(cw) * ch);  // each written once below
  std::vector<std::uint8_t> band_blocked(static_cast<std::size_t>(bands), 0), band_lit(static_cast<std::size_t>(bands), 0);
  engine::jobs::parallel_for(0, bands, 1, [&](int b0, int b1) {
    for (int b = b0; b < b1; ++b) {
      // Each cell written once from its pixels, branch-free (NaN, a
      // non-receiver, fails every comparison).
      for (int cy = b * kBandCells; cy < std::min(ch, (b + 1) * kBandCells); ++cy)
        for (int cx = 0; cx < cw; ++cx) {
          WindowSums cell{};
          for (int y = cy * kCell; y < std::min(h, cy * kCell + kCell); ++y)
            for (int x = cx * kCell; x < std::min(w, cx * kCell + kCell); ++x) {
              const float d = blocker[static_cast<std::size_t>(y) * w + x];
              const bool blocked = d < kInf, traced = blocked && d > 0;
              cell.lit += d == kInf;
              cell.blocked += blocked;
              cell.traced += traced;
              cell.inverse_distance += traced ? 1.0f / d : 0.0f;
            }
          cells[cell_at(cx, cy)] = cell;
        }
      bool any_blocked = false, any_lit = false;
      for (int cy = b * kBandCells; cy < std::min(ch, (b + 1) * kBandCells); ++cy)
        for (int cx = 0; cx < cw; ++cx) {
          any_blocked = any_blocked || cells[cell_at(cx, cy)].blocked > 0;
          any_lit = any_lit || cells[cell_at(cx, cy)].lit > 0;
        }
      band_blocked[static_cast<std::size_t>(b)] = any_blocked;
      band_lit[static_cast<std::size_t>(b)] = any_lit;
    }
  });
  // A cell's window reaches one band up and one down: its band is active
  // where those three bands hold both, and the rows of the bands beside an
  // active one are summed too.
  std::vector<std::uint8_t> active(static_cast<std::size_t>(bands), 0), summed(static_cast<std::size_t>(bands), 0);
  for (int b = 0; b < bands; ++b) {
    bool blocked = false, lit = false;
    for (int k = std::max(0, b - 1); k <= std::min(bands - 1, b + 1); ++k) {
      blocked = blocked || band_blocked[static_cast<std::size_t>(k)];
      lit = lit || band_lit[static_cast<std::size_t>(k)];
    }
    active[static_cast<std::size_t>(b)] = blocked && lit;
  }
  for (int b = 0; b < bands; ++b)
    for (int k = std::max(0, b - 1); k <= std::min(bands - 1, b + 1); ++k) summed[static_cast<std::size_t>(b)] |= active[static_cast<std::size_t>(k)];
  engine::jobs::parallel_for<std::size_t>(0, radius.size(), 16384, [&](std::size_t b, std::size_t e) {
    std::fill(radius.begin() + static_cast<std::ptrdiff_t>(b), radius.begin() + static_cast<std::ptrdiff_t>(e), std::uint8_t{0});
  });
  if (std::find(active.begin(), active.end(), 1) == active.end()) return;
  // Along the cell rows: cells [cx - 4, cx + 3]; only the summed bands' rows are written and read.
  const auto rows = std::make_unique_for_overwrite<WindowSums[]>(static_cast<std::size_t>(cw) * ch);
  engine::jobs::parallel_for(0, ch, 8, [&](int y0, int y1) {
    for (int cy = y0; cy < y1; ++cy) {
      if (!summed[static_cast<std::size_t>(cy / kBandCells)]) continue;
      const WindowSums* row = &cells[cell_at(0, cy)];
      WindowSums sum{};
      for (int cx = 0; cx < std::min(cw, kWindowCells / 2 - 1); ++cx) sum.add(row[cx], 1);
      for (int cx = 0; cx < cw; ++cx) {
        if (cx + kWindowCells / 2 - 1 < cw) sum.add(row[cx + kWindowCells / 2 - 1], 1);
        rows[cell_at(cx, cy)] = sum;
        if (cx - kWindowCells / 2 >= 0) sum.add(row[cx - kWindowCells / 2], -1);
      }
    }
  });
  // Down the cell columns, band by band (each band's float sums start
  // afresh, so rounding does not drift down the image), then each pixel's
  // radius from its cell's window and its own depth.
  engine::jobs::parallel_for(0, bands, 1, [&](int b0, int b1) {
    std::vector<WindowSums> column(static_cast<std::size_t>(cw), WindowSums{});
    for (int b = b0; b < b1; ++b) {
      if (!active[static_cast<std::size_t>(b)]) continue;
      // Each band sums its windows afresh: bands are independent, so any
      // thread may take any band and the result does not depend on it.
      std::fill(column.begin(), column.end(), WindowSums{});
      const int first = b * kBandCells;
      const auto add_row = [&](int cy, int sign) {
        if (cy < 0 || cy >= ch) return;
        const WindowSums* r = &rows[cell_at(0, cy)];
        for (int cx = 0; cx < cw; ++cx) column[static_cast<std::size_t>(cx)].add(r[cx], sign);
      };
      for (int cy = first - kWindowCells / 2; cy < first + kWindowCells / 2 - 1; ++cy) add_row(cy, 1);
      for (int cy = first; cy < std::min(ch, first + kBandCells); ++cy) {
        add_row(cy + kWindowCells / 2 - 1, 1);
        for (int cx = 0; cx < cw; ++cx) {
          const WindowSums& c = column[static_cast<std::size_t>(cx)];
          if (c.blocked == 0 || c.lit == 0 || c.traced == 0) continue;
          const float mean = static_cast<float>(c.traced) / c.inverse_distance;
          for (int y = cy * kCell; y < std::min(h, cy * kCell + kCell); ++y)
            for (int x = cx * kCell; x < std::min(w, cx * kCell + kCell); ++x) {
              const std::size_t p = static_cast<std::size_t>(y) * w + x;
              const float depth = g.guide[p].w;
              if (std::isnan(blocker[p]) || !(depth > 0)) continue;
              const float r = std::ceil(mean * tan_radius / (depth * pixel_spread));
              radius[p] = static_cast<std::uint8_t>(std::clamp(r, 1.0f, 8.0f));
            }
        }
        add_row(cy - kWindowCells / 2, -1);
      }
    }
  });
}

// Whether pixel q lies on pixel p's surface: normals within ~25 degrees, q
// within 2 % of p's depth of p's tangent plane.
struct SurfaceTest {
  const std::vector<glm::vec4>& guide;
  const std::vector<glm::vec3>& position;
  bool operator()(std::size_t p, std::size_t q) const {
    const glm::vec3 np(guide[p]), nq(guide[q]);
    return glm::dot(np, nq) > 0.9f && std::abs(glm::dot(np, position[q] - position[p])) <= 0.02f * guide[p].w;
  }
};

}  // namespace

void penumbra_filter(const GBuffer& g, std::span<const float> blocker, float tan_radius, float pixel_spread,
                     std::span<float> out) {
  const int w = g.width, h = g.height;
  const std::size_t n = blocker.size();
  if (out.size() != n) throw std::invalid_argument("penumbra_filter: out must have one value per pixel of blocker");
  engine::jobs::parallel_for<std::size_t>(0, n, 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) out[p] = std::isnan(blocker[p]) ? kNotReceiver : std::isinf(blocker[p]) ? 1.0f : 0.0f;
  });
  if (!(tan_radius > 0)) return;
  const auto radius_storage = std::make_unique_for_overwrite<std::uint8_t[]>(n);
  const std::span<std::uint8_t> radius(radius_storage.get(), n);
  penumbra_radius(g, blocker, tan_radius, pixel_spread, radius);
  const auto each_pixel = [&](auto&& fn) {
    engine::jobs::parallel_for(0, h, 4, [&](int y0, int y1) {
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < w; ++x) {
          const std::size_t p = static_cast<std::size_t>(y) * w + x;
          if (radius[p] != 0) fn(x, y, p);
        }
    });
  };
  const SurfaceTest same{g.guide, g.position};
  // A box of radius 4 or more is [-r, r - 1], an even width: 8 and 16
  // pixels hold each of the pattern's 8 columns (rows) equally often, where
  // 9 or 17 would count one more and leave its trace.
  const auto last = [](int r) { return r >= 4 ? r - 1 : r; };
  // Rows, then columns, each a box over the pixel's own radius on its own
  // surface; the columns take the rows' means (a pixel outside a penumbra
  // is its own mean). The radius changes smoothly from pixel to pixel (a
  // mean over a sliding window), so the columns read rows filtered at
  // about their own width.
  // The rows read the pattern's visibility (`out` as it stands) and the
  // columns write `out` only where they read `rows`: one copy, not two.
  const auto rows_storage = std::make_unique_for_overwrite<float[]>(n);
  float* const rows = rows_storage.get();
  engine::jobs::parallel_for<std::size_t>(0, n, 16384, [&](std::size_t b, std::size_t e) { std::copy(out.begin() + static_cast<std::ptrdiff_t>(b), out.begin() + static_cast<std::ptrdiff_t>(e), rows + b); });
  each_pixel([&](int x, int, std::size_t p) {
    float sum = 0, count = 0;
    for (int dx = -radius[p]; dx <= last(radius[p]); ++dx) {
      const int qx = x + dx;
      if (qx < 0 || qx >= w) continue;
      const std::size_t q = p + static_cast<std::size_t>(static_cast<std::ptrdiff_t>(dx));
      if (std::isnan(out[q]) || !same(p, q)) continue;
      sum += out[q];
      count += 1;
    }
    rows[p] = sum / count;
  });
  each_pixel([&](int x, int y, std::size_t p) {
    float sum = 0, count = 0;
    for (int dy = -radius[p]; dy <= last(radius[p]); ++dy) {
      const int qy = y + dy;
      if (qy < 0 || qy >= h) continue;
      const std::size_t q = static_cast<std::size_t>(qy) * w + x;
      if (std::isnan(rows[q]) || !same(p, q)) continue;
      sum += rows[q];
      count += 1;
    }
    out[p] = sum / count;
  });
}

engine::image::ImageRGB DirectTileShader::take(const GBuffer& g, RealtimeDirectStats* stats) {
  for (const SoftLight& soft : soft_) {
    const std::size_t pixels = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
    const auto lit_storage = std::make_unique_for_overwrite<float[]>(pixels);
    const std::span<float> lit(lit_storage.get(), pixels);
    penumbra_filter(g, std::span<const float>(soft.blocker.get(), pixels), soft.tan_radius, camera_.pixel_spread(), lit);
    std::atomic<std::size_t> bad{0};
    engine::jobs::parallel_for<std::size_t>(0, lit.size(), 2048, [&](std::size_t b, std::size_t e) {
      std::size_t local_bad = 0;
      for (std::size_t p = b; p < e; ++p) {
        // The BRDF along the disk's centre, only where some of it arrives:
        // most of a room's pixels that face the sun are in its shadow.
        if (!(lit[p] > 0)) continue;
        const GSample& s = g.samples[p];
        const engine::math::Frame frame = engine::math::Frame::from_normal(s.normal_world);
        const glm::vec3 wo = frame.to_local(s.wo_world), wc = frame.to_local(soft.centre.direction);
        const glm::vec3 c = engine::material::brdf_eval(s.brdf, wo, wc) * wc.z * soft.centre.radiance * lit[p];
        if (!(std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b))) {
          ++local_bad;
          continue;
        }
        out_.pixels[p] += c;
      }
      if (local_bad) bad.fetch_add(local_bad, std::memory_order_relaxed);
    });
    nonfinite_.fetch_add(bad.load(), std::memory_order_relaxed);
  }
  if (stats) {
    stats->shadow_rays = 0;
    for (const std::uint32_t n : rays_per_tile_) stats->shadow_rays += n;
    stats->lights = n_lights_;
    stats->nonfinite_pixels = nonfinite_.load();
    stats->untraced_answers = untraced_.load();
  }
  return std::move(out_);
}

engine::image::ImageRGB shade_direct_realtime(const GBuffer& g, const engine::rt::RtScene& scene,
                                              const engine::render::LightSet& lights,
                                              const engine::render::CameraRays& camera, RealtimeDirectStats* stats,
                                              engine::rt::RayBatchTracer* tracer, int pattern_phase) {
  DirectTileShader shader(scene, lights, camera, g.width, g.height, {}, pattern_phase);
  const int tiles_x = (g.width + 3) / 4, tiles_y = (g.height + 3) / 4;
  auto each_tile = [&] {
    engine::jobs::parallel_for(0, tiles_x * tiles_y, 16, [&](int t0, int t1) {
      DirectTileShader::Scratch scratch;
      for (int t = t0; t < t1; ++t) shader.shade_tile(g, t % tiles_x * 4, t / tiles_x * 4, scratch);
    });
  };
  // The shader reads `distances` and `first` in the second pass: they live
  // as long as the function.
  std::vector<engine::rt::Ray> rays;
  std::vector<std::size_t> first;
  std::vector<float> distances;
  engine::render::CameraHitTracer* raster = tracer ? tracer->camera_hit_tracer() : nullptr;
  const bool with_view =
      raster && raster->take_view_shadows(view_shadow_request(lights, pattern_phase, scene.offset_scale()), distances);
  if (with_view) {
    const std::size_t want = lights.punctual_count() * static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
    if (distances.size() != want)
      throw std::invalid_argument("shade_direct_realtime: " + std::to_string(distances.size()) + " answers from the view for " +
                                  std::to_string(want) + " (a G-buffer of another size than the view?)");
    shader.set_batch({nullptr, nullptr, nullptr, &distances});
  } else if (tracer) {
    std::vector<std::vector<engine::rt::Ray>> per_tile(static_cast<std::size_t>(tiles_x) * tiles_y);
    shader.set_batch({&per_tile, nullptr, nullptr});
    each_tile();
    first.resize(per_tile.size());
    std::size_t count = 0;
    for (std::size_t t = 0; t < per_tile.size(); ++t) {
      first[t] = count;
      count += per_tile[t].size();
    }
    rays.resize(count);
    engine::jobs::parallel_for<std::size_t>(0, per_tile.size(), 256, [&](std::size_t b, std::size_t e) {
      for (std::size_t t = b; t < e; ++t) std::copy(per_tile[t].begin(), per_tile[t].end(), rays.begin() + static_cast<std::ptrdiff_t>(first[t]));
    });
    // Closest hits, not any hit: a soft shadow's width needs the blocker's distance.
    std::vector<engine::rt::Hit> hits(rays.size());
    std::vector<std::uint8_t> found(rays.size());
    distances.resize(rays.size());
    tracer->intersect(scene, rays, hits, found);
    engine::jobs::parallel_for<std::size_t>(0, rays.size(), 4096, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) distances[i] = found[i] ? hits[i].t : kInf;
    });
    shader.set_batch({nullptr, &distances, &first});
  }
  each_tile();
  engine::image::ImageRGB out = shader.take(g, stats);
  if (stats) stats->traced_with_view = with_view;
  return out;
}

engine::render::ViewShadowRequest view_shadow_request(const engine::render::LightSet& lights, int pattern_phase,
                                                      float offset_scale) {
  engine::render::ViewShadowRequest request;
  request.pattern_shift = disk_pattern_shift(pattern_phase);
  request.offset_scale = offset_scale;
  request.lights.resize(lights.punctual_count());
  for (std::size_t l = 0; l < request.lights.size(); ++l) {
    const engine::render::PunctualInstance& light = lights.punctual_lights()[l];
    engine::render::ViewShadowLight& out = request.lights[l];
    if (light.light.type != engine::scene::PunctualLight::Type::Directional) {
      out.position = light.position;
      continue;
    }
    out.directional = true;
    out.nearest = light.angular_radius > 0.0f;
    const std::array<engine::render::LightSample, kDiskPatternCells> pattern = directional_pattern(lights, l);
    for (std::size_t i = 0; i < pattern.size(); ++i) out.directions[i] = pattern[i].direction;
  }
  return request;
}

void queue_realtime_view(engine::rt::RayBatchTracer* tracer, const engine::rt::RtScene& scene,
                         const engine::render::CameraRays& camera, const engine::render::TemporalAntialiasing& taa,
                         const engine::render::TemporalAaSettings& taa_settings, const engine::render::LightSet* lights) {
  engine::render::CameraHitTracer* raster = tracer ? tracer->camera_hit_tracer() : nullptr;
  if (!raster) return;
  // A camera cut clears the antialiasing's history, not its place in the cycle.
  const glm::vec2 jitter = taa_settings.enabled ? taa.next_jitter(taa_settings) : glm::vec2(0.0f);
  std::optional<engine::render::ViewShadowRequest> shadows;
  if (lights) shadows = view_shadow_request(*lights, taa_settings.enabled ? taa.next_phase(taa_settings) : 0, scene.offset_scale());
  raster->queue_camera_hits(scene, camera, glm::vec2(0.5f) + jitter, shadows ? &*shadows : nullptr);
}

void add_image(engine::image::ImageRGB& to, const engine::image::ImageRGB& from) {
  engine::jobs::parallel_for<std::size_t>(0, to.size(), 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) to.pixels[i] += from.pixels[i];
  });
}

}  // namespace transgi::shading
