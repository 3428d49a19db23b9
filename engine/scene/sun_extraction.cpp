#include "engine/scene/sun_extraction.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/math/sampling.h"

namespace engine::scene {

namespace {

float pixel_solid_angle(int y, int w, int h) {
  const float theta = math::kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(h);
  return (math::kTwoPi / static_cast<float>(w)) * (math::kPi / static_cast<float>(h)) * std::sin(theta);
}

}  // namespace

SunSplit split_sun(const Environment& env, const SunExtractionSettings& settings) {
  const image::ImageRGB& img = env.image();
  SunSplit out{std::nullopt, env};  // no sun: the residual is the map itself (copied, not rebuilt)
  const int w = img.width, h = img.height;
  if (w < 3 || h < 3 || !(env.strength() > 0)) return out;

  std::vector<float> lum(img.pixels.size());
  for (std::size_t i = 0; i < lum.size(); ++i) {
    const float l = math::luminance(img.pixels[i]);
    lum[i] = std::isfinite(l) ? l : 0.0f;  // a non-finite pixel never seeds a sun
  }
  const std::size_t peak = static_cast<std::size_t>(std::max_element(lum.begin(), lum.end()) - lum.begin());
  std::vector<float> sorted = lum;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
  const float median = std::max(sorted[sorted.size() / 2], 1e-6f * lum[peak]);
  if (!(lum[peak] > settings.peak_to_median * median)) return out;

  // The disk: pixels connected to the peak (8-neighbours, wrapping in u)
  // brighter than the geometric mean of peak and median, which sits far
  // above the sky and far below the disk in either's own units.
  const float threshold = std::sqrt(lum[peak] * median);
  std::vector<std::uint8_t> in(lum.size(), 0);
  std::vector<std::size_t> region{peak}, stack{peak};
  in[peak] = 1;
  float omega = 0;
  while (!stack.empty()) {
    const std::size_t p = stack.back();
    stack.pop_back();
    const int px = static_cast<int>(p % static_cast<std::size_t>(w)), py = static_cast<int>(p / static_cast<std::size_t>(w));
    omega += pixel_solid_angle(py, w, h);
    if (omega > settings.max_solid_angle) return out;  // a broad glow, not a sun: the probes keep it
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int y = py + dy;
        if (y < 0 || y >= h) continue;
        const int x = (px + dx + w) % w;
        const std::size_t q = static_cast<std::size_t>(y) * w + x;
        if (in[q] || !(lum[q] > threshold)) continue;
        in[q] = 1;
        region.push_back(q);
        stack.push_back(q);
      }
  }

  // Background under the disk: the mean of the ring of pixels around it.
  glm::dvec3 ring(0.0);
  int ring_count = 0;
  for (std::size_t p : region) {
    const int px = static_cast<int>(p % static_cast<std::size_t>(w)), py = static_cast<int>(p / static_cast<std::size_t>(w));
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int y = py + dy;
        if (y < 0 || y >= h) continue;
        const std::size_t q = static_cast<std::size_t>(y) * w + (px + dx + w) % w;
        if (in[q] == 1) continue;
        in[q] = 2;  // counted once
        ring += glm::dvec3(img.pixels[q]);
        ++ring_count;
      }
  }
  const glm::vec3 background = ring_count > 0 ? glm::vec3(ring / static_cast<double>(ring_count)) : glm::vec3(0.0f);

  ExtractedSun sun;
  glm::dvec3 irradiance(0.0), direction(0.0);
  image::ImageRGB residual = img;
  for (std::size_t p : region) {
    const int px = static_cast<int>(p % static_cast<std::size_t>(w)), py = static_cast<int>(p / static_cast<std::size_t>(w));
    const glm::vec3 excess = glm::max(img.pixels[p] - background, glm::vec3(0.0f));
    residual.pixels[p] = img.pixels[p] - excess;
    const float o = pixel_solid_angle(py, w, h);
    const glm::vec3 d = Environment::uv_to_direction(
        {(static_cast<float>(px) + 0.5f) / static_cast<float>(w), (static_cast<float>(py) + 0.5f) / static_cast<float>(h)});
    irradiance += glm::dvec3(excess * o);
    direction += glm::dvec3(d * (math::luminance(excess) * o));
    sun.solid_angle += o;
  }
  if (!(glm::length(direction) > 0)) return out;
  sun.pixels = static_cast<int>(region.size());
  sun.irradiance = glm::vec3(irradiance) * env.strength();
  sun.direction = glm::normalize(env.to_world(glm::vec3(glm::normalize(direction))));
  // Cone of equal solid angle: omega = 2 pi (1 - cos r).
  sun.angular_radius = std::acos(std::clamp(1.0f - sun.solid_angle / math::kTwoPi, -1.0f, 1.0f));
  out.sun = sun;
  const glm::mat4 matrix(glm::mat3(env.to_world({1, 0, 0}), env.to_world({0, 1, 0}), env.to_world({0, 0, 1})));
  out.residual = Environment(std::move(residual), env.strength(), matrix);
  return out;
}

}  // namespace engine::scene
