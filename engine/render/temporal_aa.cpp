#include "engine/render/temporal_aa.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "engine/jobs/parallel_for.h"

namespace engine::render {

namespace {

float radical_inverse(std::uint64_t i, std::uint64_t base) {
  float inv = 1.0f / static_cast<float>(base), f = inv, r = 0.0f;
  while (i > 0) {
    r += f * static_cast<float>(i % base);
    i /= base;
    f *= inv;
  }
  return r;
}

}  // namespace

glm::vec2 taa_jitter(std::uint64_t index, int phases) {
  const std::uint64_t i = index % static_cast<std::uint64_t>(std::max(phases, 1)) + 1;
  return {radical_inverse(i, 2) - 0.5f, radical_inverse(i, 3) - 0.5f};
}

std::vector<TaaObject> objects_of(const rt::RtScene& scene) {
  std::vector<TaaObject> out;
  scene.for_each_instance([&](const rt::InstanceRecord& inst) { out.push_back({inst.entity, inst.to_world}); });
  return out;
}

// The range of the 3x3 neighbours of each pixel of one row, per layer: at a
// silhouette it spans both sides whichever way the edge runs, so the
// jitter's alternation there stays inside it. Rows beyond the image repeat
// its edge. Separable: each of the three rows' horizontal ranges, then
// their vertical one, over flat float rows (a pixel's neighbours are 3
// floats away) so that the loops vectorise.
static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "a row of pixels is read as a row of floats");
class TemporalAntialiasing::NeighbourRange {
 public:
  // The horizontal ranges of rows [y0 - 1, y1], edges repeated, for row().
  void rows(std::span<image::ImageRGB* const> layers, int w, int h, int y0, int y1) {
    n_ = 3 * static_cast<std::size_t>(w);
    y0_ = y0;
    count_ = static_cast<std::size_t>(y1 - y0 + 2);
    layers_ = layers.size();
    h_lo_.resize(layers_ * count_ * n_);
    h_hi_.resize(layers_ * count_ * n_);
    lo_.resize(layers_ * n_);
    hi_.resize(layers_ * n_);
    for (std::size_t l = 0; l < layers_; ++l)
      for (std::size_t r = 0; r < count_; ++r) {
        const int y = std::clamp(y0 - 1 + static_cast<int>(r), 0, h - 1);
        horizontal(&layers[l]->pixels[static_cast<std::size_t>(y) * w].x, n_, &h_lo_[(l * count_ + r) * n_],
                   &h_hi_[(l * count_ + r) * n_]);
      }
    h_ = h;
  }
  // Row y's 3x3 ranges (y0 <= y < y1 of the last rows() call).
  void row(int y) {
    const std::size_t r = static_cast<std::size_t>(y - y0_);  // the row above y
    // Beyond the image the edge row repeats: the row itself stands in.
    const std::size_t above = y == 0 ? r + 1 : r, below = y == h_ - 1 ? r + 1 : r + 2;
    for (std::size_t l = 0; l < layers_; ++l) {
      const float* base_lo = &h_lo_[l * count_ * n_];
      const float* base_hi = &h_hi_[l * count_ * n_];
      const float *a = base_lo + above * n_, *b = base_lo + (r + 1) * n_, *c = base_lo + below * n_;
      float* lo = &lo_[l * n_];
      for (std::size_t i = 0; i < n_; ++i) lo[i] = std::min(std::min(a[i], b[i]), c[i]);
      a = base_hi + above * n_, b = base_hi + (r + 1) * n_, c = base_hi + below * n_;
      float* hi = &hi_[l * n_];
      for (std::size_t i = 0; i < n_; ++i) hi[i] = std::max(std::max(a[i], b[i]), c[i]);
    }
  }
  [[nodiscard]] glm::vec3 lo(std::size_t layer, int x) const { return at(lo_, layer, x); }
  [[nodiscard]] const float* lo_row(std::size_t layer) const { return &lo_[layer * n_]; }
  [[nodiscard]] const float* hi_row(std::size_t layer) const { return &hi_[layer * n_]; }
  [[nodiscard]] glm::vec3 hi(std::size_t layer, int x) const { return at(hi_, layer, x); }

 private:
  static void horizontal(const float* src, std::size_t n, float* lo, float* hi) {
    if (n == 3) {
      std::copy(src, src + 3, lo);
      std::copy(src, src + 3, hi);
      return;
    }
    for (std::size_t c = 0; c < 3; ++c) {
      lo[c] = std::min(src[c], src[c + 3]);
      hi[c] = std::max(src[c], src[c + 3]);
      lo[n - 3 + c] = std::min(src[n - 6 + c], src[n - 3 + c]);
      hi[n - 3 + c] = std::max(src[n - 6 + c], src[n - 3 + c]);
    }
    for (std::size_t i = 3; i + 3 < n; ++i) {
      lo[i] = std::min(std::min(src[i - 3], src[i]), src[i + 3]);
      hi[i] = std::max(std::max(src[i - 3], src[i]), src[i + 3]);
    }
  }
  [[nodiscard]] glm::vec3 at(const std::vector<float>& v, std::size_t layer, int x) const {
    const float* f = &v[layer * n_ + 3 * static_cast<std::size_t>(x)];
    return {f[0], f[1], f[2]};
  }
  std::vector<float> lo_, hi_, h_lo_, h_hi_;
  std::size_t n_ = 0, count_ = 0, layers_ = 0;
  int y0_ = 0, h_ = 0;
};

glm::vec2 TemporalAntialiasing::next_jitter(const TemporalAaSettings& settings) const {
  return settings.enabled ? taa_jitter(frame_, settings.jitter_phases) : glm::vec2(0.0f);
}

int TemporalAntialiasing::next_phase(const TemporalAaSettings& settings) const {
  return settings.enabled ? static_cast<int>(frame_ % static_cast<std::uint64_t>(std::max(settings.jitter_phases, 1))) : 0;
}

void TemporalAntialiasing::clear() {
  prev_ = Previous{};
  stats_ = Stats{};
  cycle_count_.clear();
  cycle_ramp_.clear();
}

void TemporalAntialiasing::plan_motion(std::span<const TaaObject> objects) {
  std::uint32_t size = 0;
  for (const TaaObject& o : objects) size = std::max(size, o.entity.index + 1);
  placed_.assign(size, Placed{});
  motion_.assign(size, Motion{});
  any_moved_ = false;
  for (const TaaObject& o : objects) {
    placed_[o.entity.index] = Placed{o.entity.generation, true, o.to_world};
    Motion& m = motion_[o.entity.index];
    m.generation = o.entity.generation;
    if (o.entity.index >= prev_.placed.size()) continue;
    const Placed& then = prev_.placed[o.entity.index];
    if (!then.present || then.generation != o.entity.generation || then.to_world == o.to_world) continue;
    m.moved = true;
    m.back = then.to_world * o.to_world.inverse();
    any_moved_ = true;
  }
}

void TemporalAntialiasing::mark_near_moved() {
  near_moved_.clear();
  if (!any_moved_) return;
  const int w = prev_.camera->width(), h = prev_.camera->height();
  const std::size_t n = prev_.entity.size();
  std::vector<std::uint8_t> own(n), row_has(static_cast<std::size_t>(h), 0);
  near_moved_.assign(n, 0);
  jobs::parallel_for(0, h, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      std::uint8_t any = 0;
      for (int x = 0; x < w; ++x) {
        const std::size_t q = static_cast<std::size_t>(y) * w + x;
        own[q] = moved(prev_.entity[q]) ? 1 : 0;
        any |= own[q];
      }
      row_has[static_cast<std::size_t>(y)] = any;
    }
  });
  // Dilated by one pixel, only on the rows around those that showed one.
  jobs::parallel_for(0, h, 16, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const int lo = std::max(0, y - 1), hi = std::min(h - 1, y + 1);
      bool near = false;
      for (int r = lo; r <= hi; ++r) near = near || row_has[static_cast<std::size_t>(r)];
      if (!near) continue;
      for (int x = 0; x < w; ++x) {
        std::uint8_t any = 0;
        for (int r = lo; r <= hi; ++r)
          for (int dx = std::max(0, x - 1); dx <= std::min(w - 1, x + 1); ++dx) any |= own[static_cast<std::size_t>(r) * w + dx];
        near_moved_[static_cast<std::size_t>(y) * w + x] = any;
      }
    }
  });
}

bool TemporalAntialiasing::moved_beside(std::size_t q, ecs::Entity self) const {
  const int w = prev_.camera->width(), h = prev_.camera->height();
  const int x = static_cast<int>(q % static_cast<std::size_t>(w)), y = static_cast<int>(q / static_cast<std::size_t>(w));
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int qx = x + dx, qy = y + dy;
      if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
      const ecs::Entity e = prev_.entity[static_cast<std::size_t>(qy) * w + qx];
      if (e != self && moved(e)) return true;
    }
  return false;
}

void TemporalAntialiasing::keep_history(const CameraRays& camera, TaaSurfaces& surfaces,
                                        std::span<image::ImageRGB* const> layers) {
  const std::size_t n = surfaces.position.size();
  prev_.camera = camera;
  prev_.position.swap(surfaces.position);
  prev_.guide.swap(surfaces.guide);
  prev_.entity.swap(surfaces.entity);
  // The caller gets storage of this frame's size back.
  surfaces.position.resize(n);
  surfaces.guide.resize(n);
  surfaces.entity.resize(n);
  prev_.layers.resize(layers.size());
  for (std::size_t l = 0; l < layers.size(); ++l) {
    prev_.layers[l].width = layers[l]->width;
    prev_.layers[l].height = layers[l]->height;
    prev_.layers[l].pixels.resize(n);
  }
  jobs::parallel_for<std::size_t>(0, n, 16384, [&](std::size_t b, std::size_t e) {
    for (std::size_t l = 0; l < layers.size(); ++l)
      std::copy(layers[l]->pixels.begin() + static_cast<std::ptrdiff_t>(b), layers[l]->pixels.begin() + static_cast<std::ptrdiff_t>(e),
                prev_.layers[l].pixels.begin() + static_cast<std::ptrdiff_t>(b));
  });
  prev_.placed.swap(placed_);
  prev_.frames.swap(frames_);
  if (prev_.frames.size() != n) prev_.frames.assign(n, 1);
}

std::size_t TemporalAntialiasing::blend_still_row(std::size_t row, int w, const std::vector<ecs::Entity>& entity,
                                                  std::span<image::ImageRGB* const> layers,
                                                  const NeighbourRange& range, float clamp_amount, float blend,
                                                  const TemporalAaSettings& settings, std::vector<std::uint8_t>& plain,
                                                  std::vector<float>& alpha3) {
  // Which pixels are plain: their surface did not move, and their history,
  // at the pixel itself, shows no object that did.
  std::size_t count = 0;
  for (int x = 0; x < w; ++x) {
    const std::size_t p = row + static_cast<std::size_t>(x);
    const ecs::Entity self = entity[p], was = prev_.entity[p];
    const bool is_plain = !moved(self) && (was == self || !moved(was)) && !(!near_moved_.empty() && near_moved_[p] && moved_beside(p, self));
    plain[static_cast<std::size_t>(x)] = is_plain ? 1 : 0;
    float alpha = 1.0f;
    if (is_plain) {
      still_plain_[p] = 1;
      frames_[p] = static_cast<std::uint8_t>(std::min(255, prev_.frames[p] + 1));
      alpha = std::max(blend, 1.0f / static_cast<float>(frames_[p]));
      ++count;
    }
    alpha3[3 * static_cast<std::size_t>(x)] = alpha3[3 * static_cast<std::size_t>(x) + 1] = alpha3[3 * static_cast<std::size_t>(x) + 2] = alpha;
  }
  if (count == 0) return 0;
  // Every pixel of the row as if plain, in flat float rows (vectorised);
  // resolve() overwrites the others.
  const std::size_t n = 3 * static_cast<std::size_t>(w);
  const float margin_scale = settings.clamp_margin * 0.5f;
  for (std::size_t l = 0; l < layers.size(); ++l) {
    const float* history = &prev_.layers[l].pixels[row].x;
    const float* cur = &layers[l]->pixels[row].x;
    float* out = &out_[l].pixels[row].x;
    const float* a = alpha3.data();
    if (clamp_amount > 0.0f) {
      const float *lo = range.lo_row(l), *hi = range.hi_row(l);
      for (std::size_t i = 0; i < n; ++i) {
        const float margin = margin_scale * (std::abs(lo[i]) + std::abs(hi[i]));
        float kept = history[i];
        kept += clamp_amount * (std::min(std::max(kept, lo[i] - margin), hi[i] + margin) - kept);
        out[i] = kept + a[i] * (cur[i] - kept);
      }
    } else {
      for (std::size_t i = 0; i < n; ++i) out[i] = history[i] + a[i] * (cur[i] - history[i]);
    }
  }
  return count;
}

void TemporalAntialiasing::resolve(const CameraRays& camera, TaaSurfaces surfaces, std::span<const TaaObject> objects,
                                   std::span<image::ImageRGB* const> layers, const TemporalAaSettings& settings,
                                   bool light_changed) {
  if (layers.size() > kMaxLayers) throw std::invalid_argument("TemporalAntialiasing::resolve: at most 4 layers");
  const int w = camera.width(), h = camera.height();
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const glm::vec2 jitter = next_jitter(settings);
  const int phases = std::max(settings.jitter_phases, 1);
  const std::uint64_t phase = frame_ % static_cast<std::uint64_t>(phases);  // of the frame resolved now
  ++frame_;
  plan_motion(objects);
  const bool have_history = prev_.camera && prev_.camera->width() == w && prev_.camera->height() == h &&
                            prev_.layers.size() == layers.size() && prev_.position.size() == n;
  if (!have_history) {
    stats_ = Stats{};
    keep_history(camera, surfaces, layers);
    return;
  }
  out_.resize(layers.size());
  frames_.resize(n);
  still_plain_.assign(n, 0);
  mark_near_moved();
  for (std::size_t l = 0; l < layers.size(); ++l) out_[l].pixels.resize(n);
  const CameraRays& before = *prev_.camera;
  const float blend = std::clamp(settings.blend, 0.0f, 1.0f);
  const bool camera_still = before.to_world() == camera.to_world();
  std::atomic<std::size_t> reused{0}, rejected{0};
  // Where some pixel's history may be clamped, each row's 3x3 range per
  // layer is found first, as flat float rows the compiler vectorises.
  const bool may_clamp = light_changed || !camera_still || any_moved_;
  const bool rows_first = camera_still && settings.vectorised_rows;
  jobs::parallel_for(0, h, 16, [&](int y0, int y1) {
    std::size_t local_reused = 0, local_rejected = 0;
    NeighbourRange range;
    std::vector<std::uint8_t> plain(static_cast<std::size_t>(w));
    std::vector<float> alpha3(3 * static_cast<std::size_t>(w));
    if (may_clamp) range.rows(layers, w, h, y0, y1);
    for (int y = y0; y < y1; ++y) {
      if (may_clamp) range.row(y);
      const std::size_t row = static_cast<std::size_t>(y) * w;
      if (rows_first) local_reused += blend_still_row(row, w, surfaces.entity, layers, range, light_changed ? 1.0f : 0.0f, blend, settings, plain, alpha3);
      for (int x = 0; x < w; ++x) {
        if (rows_first && plain[static_cast<std::size_t>(x)]) continue;
        const std::size_t p = row + x;
        // Where this pixel's point was in the previous frame, carried by
        // its object's motion. The point was traced through the jittered
        // film position; the pixel's centre is `jitter` away from it in
        // both frames, so a still view reads its history at the pixel
        // itself (no resampling blur).
        const ecs::Entity self = surfaces.entity[p];  // null for a miss
        const bool hit = !self.is_null();
        const bool self_moved = hit && moved(self);
        glm::vec2 film(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
        bool on_film = true;
        // Position and normal are read only where the point moved on screen.
        glm::vec3 position(0.0f), normal(0.0f);
        if (!camera_still || self_moved) {
          position = surfaces.position[p];
          normal = glm::vec3(surfaces.guide[p]);
          if (self_moved) {
            const transform::Similarity& back = motion_[self.index].back;
            position = back.apply_point(position);
            normal = back.apply_direction(normal);
          }
          std::optional<glm::vec2> f;
          if (hit) {
            f = before.project(position);
            if (f) *f -= jitter;
          } else {
            f = before.project(before.position() + camera.generate(film).direction);
          }
          on_film = f.has_value();
          if (f) film = *f;
        }
        const glm::vec2 motion = film - glm::vec2(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
        const bool still = !self_moved && glm::dot(motion, motion) < 0.05f * 0.05f;
        // The previous frame's pixels around that point, bilinearly, each
        // only where it showed this surface.
        float weight = 0.0f, best = 0.0f;
        std::uint8_t frames = 0;  // how many frames the history holds (its main tap's)
        glm::vec3 history[kMaxLayers] = {};
        if (camera_still && !self_moved) {
          // Most pixels of a still camera: the pixel itself, one tap.
          const ecs::Entity was = prev_.entity[p];
          if ((was == self || !moved(was)) && !(!near_moved_.empty() && near_moved_[p] && moved_beside(p, self))) {
            weight = 1.0f;
            still_plain_[p] = 1;
            frames = prev_.frames[p];
            for (std::size_t l = 0; l < layers.size(); ++l) history[l] = prev_.layers[l].pixels[p];
          }
        } else if (on_film) {
          const float fx = film.x - 0.5f, fy = film.y - 0.5f;
          const int x0 = static_cast<int>(std::floor(fx)), y0t = static_cast<int>(std::floor(fy));
          const float tx = fx - static_cast<float>(x0), ty = fy - static_cast<float>(y0t);
          for (int k = 0; k < 4; ++k) {
            const float wk = ((k & 1) ? tx : 1.0f - tx) * ((k >> 1) ? ty : 1.0f - ty);
            const int qx = x0 + (k & 1), qy = y0t + (k >> 1);
            if (wk <= 0.0f || qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
            const std::size_t q = static_cast<std::size_t>(qy) * w + qx;
            const ecs::Entity was = prev_.entity[q];
            bool match;
            const bool ghost_beside = !self_moved && !near_moved_.empty() && near_moved_[q] && moved_beside(q, self);
            if (was != self || ghost_beside) {
              // Another surface was seen there. Across a still silhouette
              // that is the other side of the pixel's own edge (the jitter
              // sees one or the other): keep it, that is the antialiasing.
              // Where either object moved, it is a ghost; so is an edge
              // pixel beside an object that moved, whose history averaged
              // that object in.
              match = !self_moved && !moved(was) && !ghost_beside;
            } else if (!hit || still) {
              match = true;
            } else {
              // The same object, carried: the same tangent plane and normal.
              const glm::vec4& g = prev_.guide[q];
              const glm::vec3 nq(g);
              match = glm::dot(nq, normal) > 0.9f && std::abs(glm::dot(nq, position - prev_.position[q])) <= 0.02f * g.w;
            }
            if (!match) continue;
            weight += wk;
            if (wk > best) {
              best = wk;
              frames = prev_.frames[q];
            }
            for (std::size_t l = 0; l < layers.size(); ++l) history[l] += wk * prev_.layers[l].pixels[q];
          }
        }
        if (weight < 1e-3f) {
          // Nothing there showed this surface: the pixel restarts.
          if (hit) ++local_rejected;
          for (std::size_t l = 0; l < layers.size(); ++l) out_[l].pixels[p] = layers[l]->pixels[p];
          frames_[p] = 1;
          continue;
        }
        ++local_reused;
        // Less of the history where only part of it matched; clamped in
        // full once the point moves a quarter pixel or the light changed,
        // not at all where neither.
        // A young history is the plain mean of its frames (no first frame
        // weighing on for long); a full one blends at `blend`.
        frames_[p] = static_cast<std::uint8_t>(std::min(255, frames + 1));
        const float alpha = std::max(blend + (1.0f - blend) * std::max(0.0f, 1.0f - weight), 1.0f / static_cast<float>(frames_[p]));
        const float clamp_amount = light_changed ? 1.0f : std::min(1.0f, 4.0f * glm::length(motion));
        for (std::size_t l = 0; l < layers.size(); ++l) {
          const image::ImageRGB& cur = *layers[l];
          glm::vec3 kept = history[l] / weight;
          if (clamp_amount > 0.0f) {
            glm::vec3 lo = range.lo(l, x), hi = range.hi(l, x);
            const glm::vec3 margin = settings.clamp_margin * 0.5f * (glm::abs(lo) + glm::abs(hi));
            lo -= margin;
            hi += margin;
            kept += clamp_amount * (glm::clamp(kept, lo, hi) - kept);
          }
          out_[l].pixels[p] = kept + alpha * (cur.pixels[p] - kept);
        }
      }
    }
    reused.fetch_add(local_reused, std::memory_order_relaxed);
    rejected.fetch_add(local_rejected, std::memory_order_relaxed);
  });
  stats_ = Stats{reused.load(), rejected.load()};
  if (settings.cycle_mean) apply_cycle_mean(layers, phases, phase, light_changed);
  for (std::size_t l = 0; l < layers.size(); ++l) layers[l]->pixels.swap(out_[l].pixels);
  keep_history(camera, surfaces, layers);
}

void TemporalAntialiasing::apply_cycle_mean(std::span<image::ImageRGB* const> layers, int phases, std::uint64_t phase,
                                            bool light_changed) {
  const std::size_t n = still_plain_.size();
  if (cycle_count_.size() != n || cycle_sum_.size() != layers.size() || (n && cycle_sum_[0].pixels.size() != n)) {
    cycle_count_.assign(n, 0);
    cycle_ramp_.assign(n, 0);
    const image::ImageRGB blank(layers[0]->width, layers[0]->height);
    cycle_sum_.assign(layers.size(), blank);
    cycle_from_.assign(layers.size(), blank);
    cycle_to_.assign(layers.size(), blank);
  }
  const auto full = static_cast<std::uint8_t>(std::clamp(phases, 1, 254));
  const float inv = 1.0f / static_cast<float>(full);
  jobs::parallel_for<std::size_t>(0, n, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t p = b; p < e; ++p) {
      if (!still_plain_[p] || light_changed) {
        cycle_count_[p] = cycle_ramp_[p] = 0;
        continue;
      }
      // This frame's own sample (before the blend) joins the cycle's sum.
      if (phase == 0 || cycle_count_[p] > 0) {
        for (std::size_t l = 0; l < layers.size(); ++l)
          cycle_sum_[l].pixels[p] = (phase == 0 ? glm::vec3(0.0f) : cycle_sum_[l].pixels[p]) + layers[l]->pixels[p];
        cycle_count_[p] = phase == 0 ? 1 : static_cast<std::uint8_t>(cycle_count_[p] + 1);
        if (cycle_count_[p] == full) {
          // A whole cycle: fade from what the pixel shows now to its mean.
          for (std::size_t l = 0; l < layers.size(); ++l) {
            const glm::vec3 shown = cycle_ramp_[p] ? cycle_from_[l].pixels[p] + (cycle_to_[l].pixels[p] - cycle_from_[l].pixels[p]) *
                                                                                    (static_cast<float>(std::min(cycle_ramp_[p], full)) * inv)
                                                   : out_[l].pixels[p];
            cycle_from_[l].pixels[p] = shown;
            cycle_to_[l].pixels[p] = cycle_sum_[l].pixels[p] * inv;
          }
          cycle_count_[p] = 0;
          for (std::size_t l = 0; l < layers.size(); ++l) out_[l].pixels[p] = cycle_from_[l].pixels[p];
          cycle_ramp_[p] = 1;  // shown: from; the next frames walk to the mean
          continue;
        }
      }
      if (cycle_ramp_[p]) {
        cycle_ramp_[p] = static_cast<std::uint8_t>(std::min(cycle_ramp_[p] + 1, full + 1));
        const float t = static_cast<float>(std::min(cycle_ramp_[p] - 1, static_cast<int>(full))) * inv;
        for (std::size_t l = 0; l < layers.size(); ++l)
          out_[l].pixels[p] = cycle_from_[l].pixels[p] + (cycle_to_[l].pixels[p] - cycle_from_[l].pixels[p]) * t;
      }
    }
  });
}

}  // namespace engine::render
