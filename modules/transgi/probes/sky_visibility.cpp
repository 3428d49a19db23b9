#include "probes/sky_visibility.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>

#include "engine/jobs/parallel_for.h"
#include "engine/math/sampling.h"
#include "engine/math/sh.h"

namespace transgi::probes {

void record_sky_ray(SkyCell* cells, const SkyVisibilitySettings& settings, const glm::vec3& direction, bool escaped) {
  record_sky_ray(cells[settings.cells.cell_of(direction)], escaped, std::clamp(settings.history_rays, 1, 255));
}

void shorten_sky_history(SkyCell* cells, const SkyVisibilitySettings& settings, int rays) {
  const auto r = static_cast<std::uint8_t>(std::clamp(rays, 1, 255));
  for (int t = 0; t < settings.cells.count(); ++t) cells[t].rays = std::min(cells[t].rays, r);
}

namespace {

// FNV-1a over every pixel's bits: one pass over the map, so it runs only
// when the map object or its storage is new (maps are not edited in place).
std::uint64_t fingerprint_of(const engine::image::ImageRGB& image) {
  std::uint64_t h = 1469598103934665603ull;
  const auto* bytes = reinterpret_cast<const std::uint32_t*>(image.pixels.data());
  const std::size_t words = image.pixels.size() * 3;
  for (std::size_t i = 0; i < words; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  return h;
}

// Every map texel's patch binned into the cell holding each of its
// sub-cells (engine::scene::for_each_patch_sample: the rule of the whole
// map's projection, so the cells sum to it). Bands of rows in parallel, each
// into its own sums, added in band order: the same whatever the threads.
std::vector<float> project_cells(const engine::scene::Environment& env, const SkyCells& cells) {
  using namespace engine;
  const image::ImageRGB& image = env.image();
  const std::size_t count = static_cast<std::size_t>(cells.count());
  constexpr int kBands = 8;
  std::vector<std::vector<double>> band_sums(kBands);
  jobs::parallel_for(0, kBands, 1, [&](int b0, int b1) {
    for (int b = b0; b < b1; ++b) {
      std::vector<double>& acc = band_sums[static_cast<std::size_t>(b)];
      acc.assign(count * 75, 0.0);
      const int y0 = image.height * b / kBands, y1 = image.height * (b + 1) / kBands;
      scene::for_each_patch_sample(env, y0, y1, [&](int x, int y, const glm::vec3& dir, double d_omega) {
        const glm::vec3 L = image.at(x, y);  // at unit strength
        const math::ShBasis Y = math::sh_eval(dir);
        double* cell = acc.data() + static_cast<std::size_t>(cells.cell_of(dir)) * 75;
        for (int c = 0; c < 3; ++c) {
          const double l = static_cast<double>(L[c]) * d_omega;
          for (int k = 0; k < 25; ++k) cell[c * 25 + k] += l * static_cast<double>(Y[static_cast<std::size_t>(k)]);
        }
      });
    }
  });
  std::vector<float> per_cell(count * 75);
  for (std::size_t i = 0; i < per_cell.size(); ++i) {
    double sum = 0;
    for (const std::vector<double>& band : band_sums) sum += band[i];
    per_cell[i] = static_cast<float>(sum);
  }
  return per_cell;
}

// The last projection made, for the next field that asks for the same sky
// (the cascades' fields all see one sky).
struct SharedProjection {
  std::mutex mutex;
  SkyProjection::Key key;
  std::shared_ptr<const std::vector<float>> per_cell;
  // The map object and pixel storage last fingerprinted, so an unchanged
  // map is not hashed every frame.
  const void* fingerprinted = nullptr;
  const void* fingerprinted_pixels = nullptr;
  std::uint64_t fingerprint = 0;
};
SharedProjection& shared_projection() {
  static SharedProjection shared;
  return shared;
}

}  // namespace

bool SkyProjection::refresh(const engine::scene::Environment* env, const SkyVisibilitySettings& settings) {
  if (!env || !env->valid()) {
    const bool changed = strength_ != 0.0f || per_cell_;
    per_cell_.reset();
    strength_ = 0.0f;
    key_ = Key{};
    return changed;
  }
  const bool strength_changed = strength_ != env->strength();
  strength_ = env->strength();
  SharedProjection& shared = shared_projection();
  std::unique_lock lock(shared.mutex);
  const engine::image::ImageRGB& image = env->image();
  // Hash the pixels when the map object or its storage is not the one last
  // hashed (pixels are not edited in place: an edit builds a new map).
  if (shared.fingerprinted != static_cast<const void*>(env) || shared.fingerprinted_pixels != image.pixels.data() ||
      !shared.per_cell) {
    shared.fingerprint = fingerprint_of(image);
    shared.fingerprinted = env;
    shared.fingerprinted_pixels = image.pixels.data();
  }
  const Key key{image.width, image.height, shared.fingerprint, env->to_world_matrix(), settings.cells};
  if (key == key_ && per_cell_) return strength_changed;
  if (!(key == shared.key) || !shared.per_cell) {
    // Projected outside the lock (it runs parallel jobs).
    lock.unlock();
    auto made = std::make_shared<const std::vector<float>>(project_cells(*env, key.cells));
    lock.lock();
    shared.per_cell = std::move(made);
    shared.key = key;
  }
  per_cell_ = shared.per_cell;
  key_ = key;
  return true;
}

const std::vector<float>& SkyProjection::per_cell() const {
  static const std::vector<float> kNone;
  return per_cell_ ? *per_cell_ : kNone;
}

glm::vec3 SkyCells::direction(float u, float v) {
  const float y = 1.0f - 2.0f * v, r = std::sqrt(std::max(0.0f, 1.0f - y * y));
  const float phi = 2.0f * engine::math::kPi * u;
  return {r * std::sin(phi), y, -r * std::cos(phi)};  // u = atan2(x, -z) / 2 pi
}

void SkyProjection::add_sky_light(const SkyCell* cells, float* out) const {
  if (!has_sky()) return;
  const int count = key_.cells.count();
  const std::vector<float>& per_cell = *per_cell_;
  // The mean escaped fraction of the cells rays reached (equal areas), for those none has.
  std::uint64_t seen = 0;
  int seen_cells = 0;
  for (int t = 0; t < count; ++t) {
    if (cells[t].rays == 0) continue;
    seen += cells[t].escaped;
    ++seen_cells;
  }
  const float unseen = seen_cells > 0 ? static_cast<float>(static_cast<double>(seen) / seen_cells) : 0.0f;
  std::array<float, 75> acc{};
  for (int t = 0; t < count; ++t) {
    const float f = cells[t].rays > 0 ? static_cast<float>(cells[t].escaped) : unseen;
    if (f == 0.0f) continue;
    const float* p = per_cell.data() + static_cast<std::size_t>(t) * 75;
    for (int i = 0; i < 75; ++i) acc[static_cast<std::size_t>(i)] += f * p[i];
  }
  const float scale = strength_ / 65535.0f;
  for (int i = 0; i < 75; ++i) out[i] += scale * acc[static_cast<std::size_t>(i)];
}

}  // namespace transgi::probes
