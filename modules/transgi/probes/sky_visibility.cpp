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

std::vector<float> project_cells(const engine::scene::Environment& env, const SkyCells& cells, int sub) {
  using namespace engine;
  const image::ImageRGB& image = env.image();
  const int count = cells.count();
  std::vector<float> per_cell(static_cast<std::size_t>(count) * 75, 0.0f);
  const glm::mat3 to_local = env.to_local_matrix();
  // Equal-area cells: every sub-sample holds the same solid angle.
  const double d_omega = 4.0 * math::kPi / (static_cast<double>(count) * sub * sub);
  jobs::parallel_for(0, count, 16, [&](int b, int e) {
    for (int t = b; t < e; ++t) {
      const int x = t % cells.width, y = t / cells.width;
      std::array<double, 75> acc{};
      for (int sy = 0; sy < sub; ++sy)
        for (int sx = 0; sx < sub; ++sx) {
          const glm::vec3 world = SkyCells::direction(
              (static_cast<float>(x) + (static_cast<float>(sx) + 0.5f) / static_cast<float>(sub)) / static_cast<float>(cells.width),
              (static_cast<float>(y) + (static_cast<float>(sy) + 0.5f) / static_cast<float>(sub)) / static_cast<float>(cells.height));
          // The map's pixel at unit strength (Environment::radiance without its strength).
          const glm::vec2 uv = scene::Environment::direction_to_uv(glm::normalize(to_local * world));
          const int px = std::min(image.width - 1, static_cast<int>(uv.x * static_cast<float>(image.width)));
          const int py = std::min(image.height - 1, static_cast<int>(uv.y * static_cast<float>(image.height)));
          const glm::vec3 L = image.at(px, py);
          const math::ShBasis Y = math::sh_eval(world);
          for (int k = 0; k < 25; ++k)
            for (int c = 0; c < 3; ++c)
              acc[static_cast<std::size_t>(c * 25 + k)] += static_cast<double>(L[c] * Y[static_cast<std::size_t>(k)]) * d_omega;
        }
      for (int i = 0; i < 75; ++i)
        per_cell[static_cast<std::size_t>(t) * 75 + static_cast<std::size_t>(i)] = static_cast<float>(acc[static_cast<std::size_t>(i)]);
    }
  });
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
  const Key key{image.width, image.height, shared.fingerprint, env->to_world_matrix(), settings.cells,
                std::max(1, settings.projection_subsamples)};
  if (key == key_ && per_cell_) return strength_changed;
  if (!(key == shared.key) || !shared.per_cell) {
    // Projected outside the lock (it runs parallel jobs).
    lock.unlock();
    auto made = std::make_shared<const std::vector<float>>(project_cells(*env, key.cells, key.subsamples));
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
