#pragma once
// The sky a probe sees, split into what its rays can tell and what they need
// not estimate: per direction cell, the fraction of the probe's rays that
// escaped (its view of the sky through windows and openings), times the
// environment's exact SH projection over that cell.
//
// Why: a probe's direct sky light used to be a Monte Carlo projection of the
// radiance its escaped rays saw. Indoors about one ray in a hundred leaves
// through a window, so each probe's estimate was a handful of rays and
// neighbouring probes disagreed by tens of percent: cloudy patches a probe
// cell wide on every wall the window lights, frozen once the probes
// converge. Here a cell wholly inside the window reads 1 after its first ray
// and a cell of wall 0, so only the window's outline is estimated; the sky's
// radiance is integrated exactly; and a changed sky (strength, a new map)
// re-lights every probe at once instead of restarting its history.
#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "engine/scene/environment.h"
#include "probes/radiance_map.h"

namespace transgi::probes {

// One direction cell's record of a probe's rays: the escaped fraction in
// 1/65535ths over the last `rays` rays (a running mean, capped).
struct SkyCell {
  std::uint16_t escaped = 0;
  std::uint8_t rays = 0;  // 0 = no ray has landed in the cell yet
  std::uint8_t pad = 0;
};

// Direction cells of equal solid angle (world space): columns by azimuth,
// rows by height (y), so every cell gets the same share of a probe's
// uniform rays. (Latitude-longitude cells near the poles are a sixth of the
// mean and went unseen for many frames.)
struct SkyCells {
  int width = 32;
  int height = 16;

  [[nodiscard]] int count() const { return width * height; }
  [[nodiscard]] int cell_of(const glm::vec3& unit_dir) const {
    const float u = fast_atan2(unit_dir.x, -unit_dir.z) * 0.15915494f;  // / 2 pi, as Environment's u
    const float uw = u < 0 ? u + 1.0f : u;
    const float v = 0.5f * (1.0f - unit_dir.y);
    const int x = std::min(width - 1, std::max(0, static_cast<int>(uw * static_cast<float>(width))));
    const int y = std::min(height - 1, std::max(0, static_cast<int>(v * static_cast<float>(height))));
    return y * width + x;
  }
  // The direction at (u, v) in [0, 1)^2 of the cell grid.
  [[nodiscard]] static glm::vec3 direction(float u, float v);
  bool operator==(const SkyCells&) const = default;
};

struct SkyVisibilitySettings {
  // Finer = a window's outline resolved more exactly, at the cost of more
  // rays before every cell has seen one (unseen cells read the probe's mean
  // fraction).
  SkyCells cells{32, 16};
  // Rays a cell averages over. Higher = steadier outlines of windows, at
  // the cost of a slower response where an opening changes partly within a
  // cell (a cell whose rays all agreed restarts at the first ray that
  // disagrees, so a door that closes a whole cell is seen at once).
  int history_rays = 32;
  bool operator==(const SkyVisibilitySettings&) const = default;
};

// A cell whose last this many rays all agreed (wall or open sky) and whose
// next ray disagrees restarts: the geometry moved across it. (A few
// agreeing rays in a row are common on a window's outline.)
inline constexpr int kSkyCertainRays = 8;

// Records one ray in its cell (`history_rays` in [1, 255]). Integer
// arithmetic, rounded: it runs once per probe ray.
inline void record_sky_ray(SkyCell& c, bool escaped, int history_rays) {
  const int x = escaped ? 65535 : 0, e = c.escaped;
  const bool certain = c.rays >= kSkyCertainRays && (e == 0 || e == 65535);
  if (c.rays == 0 || (certain && e != x)) {
    c.escaped = static_cast<std::uint16_t>(x);
    c.rays = 1;
    return;
  }
  const int rays = std::min(history_rays, c.rays + 1), d = x - e;
  c.rays = static_cast<std::uint8_t>(rays);
  c.escaped = static_cast<std::uint16_t>(e + (d >= 0 ? d + rays / 2 : d - rays / 2) / rays);
}
// Records one ray of a probe in its cells, by direction.
void record_sky_ray(SkyCell* cells, const SkyVisibilitySettings& settings, const glm::vec3& direction, bool escaped);
// Every cell seen by at most `rays` rays, so the next ones count more (the
// geometry near the probe moved).
void shorten_sky_history(SkyCell* cells, const SkyVisibilitySettings& settings, int rays);

// The environment's SH projection per cell (cells x 75, [c * 25 + k]) at unit
// strength, integrated texel by texel as the whole map's projection is
// (engine::scene::for_each_patch_sample), recomputed only when the map or
// its orientation changes (its strength only rescales).
class SkyProjection {
 public:
  // Returns whether the projection or the strength changed since the last
  // call (so every probe's sky light must be re-evaluated). Null = no sky.
  bool refresh(const engine::scene::Environment* env, const SkyVisibilitySettings& settings);
  [[nodiscard]] bool has_sky() const { return strength_ > 0 && per_cell_ && !per_cell_->empty(); }
  // Adds the sky light a probe with these cells sees (75 values) to out.
  // Cells no ray has reached count with the probe's mean escaped fraction.
  void add_sky_light(const SkyCell* cells, float* out75) const;
  // cells x 75 at unit strength (tests).
  [[nodiscard]] const std::vector<float>& per_cell() const;

  // What a projection depends on: the map's size, a fingerprint of its
  // pixels, its orientation and the cells. Not its address: the light set
  // rebuilds the residual of a split sun whenever the sky is edited, into new
  // storage with the same pixels, and storage freed may be reused.
  struct Key {
    int width = 0, height = 0;
    std::uint64_t fingerprint = 0;
    glm::mat3 to_world{0.0f};
    SkyCells cells{0, 0};
    bool operator==(const Key&) const = default;
  };

 private:
  std::shared_ptr<const std::vector<float>> per_cell_;  // shared by every field that sees the same sky
  float strength_ = 0.0f;
  Key key_;
};

}  // namespace transgi::probes
