#include "ddgi/ddgi_blend.h"

#include <algorithm>
#include <cmath>

namespace transgi::ddgi {

namespace {
float max_component(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
// A texel stored with the maps' gamma, re-encoded with RTXGI's 5.
glm::vec3 to_change_encoding(const glm::vec3& stored, float gamma) {
  return gamma == kRtxgiGamma ? stored : glm::pow(glm::max(stored, glm::vec3(0.0f)), glm::vec3(gamma / kRtxgiGamma));
}
}  // namespace

void blend_irradiance(OctahedralMap<glm::vec3>& map, const std::vector<RayRecord>& rays, const DdgiSettings& s, float hysteresis,
                      bool clamp_brightness) {
  const int n = map.interior;
  // RTXGI counts back-face rays in every texel's thread; the count is the
  // probe's, so count once: a probe at or past the limit (inside geometry)
  // keeps its irradiance as it was.
  const auto max_backfaces = static_cast<int>(static_cast<float>(s.rays_per_probe) * s.random_ray_backface_threshold);
  const auto backfaces = std::count_if(rays.begin(), rays.end(), [](const RayRecord& r) { return r.distance < 0; });
  if (backfaces > 0 && backfaces >= max_backfaces) return;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const glm::vec3 texel_dir = texel_direction(x, y, n);
      glm::vec3 sum(0.0f);
      float weight_sum = 0.0f;
      for (const RayRecord& r : rays) {
        if (r.distance < 0) continue;  // back-face hits carry no radiance
        const float w = std::max(0.0f, glm::dot(texel_dir, r.direction));
        sum += r.radiance * w;
        weight_sum += w;
      }
      // Dividing by sum(cos) instead of N lowers the variance; the factor
      // 1/2 (and 2 pi when sampling) turns the cosine-weighted mean
      // radiance, E / pi, into E / (2 pi).
      const float epsilon = static_cast<float>(s.rays_per_probe) * 1e-9f;
      glm::vec3 result = sum / (2.0f * std::max(weight_sum, epsilon));
      result = glm::pow(result, glm::vec3(1.0f / s.irradiance_gamma));
      glm::vec3& texel = map.at(x + 1, y + 1);
      const glm::vec3 previous = texel;
      float h = hysteresis;
      glm::vec3 delta = result - previous;
      // RTXGI's change tests, judged in its gamma-5 encoding whatever the
      // maps' (to_change_encoding), so their thresholds mean what RTXGI's do
      // and do not depend on how bright the scene is.
      const glm::vec3 old_judged = to_change_encoding(previous, s.irradiance_gamma);
      const glm::vec3 new_judged = to_change_encoding(result, s.irradiance_gamma);
      if (max_component(old_judged - new_judged) > s.irradiance_threshold) h = std::max(0.0f, h - 0.75f);
      if (clamp_brightness && glm::length(new_judged - old_judged) > s.brightness_threshold) {
        result = previous + delta * 0.25f;
        delta = result - previous;
      }
      glm::vec3 lerp_delta = (1.0f - h) * delta;
      if (s.irradiance_gamma == kRtxgiGamma && max_component(result) < max_component(previous)) {
        // RTXGI's maps: darkening steps at least 1/1024 per frame so its
        // 10-bit formats reach the target. Not on other maps: in linear
        // units the floor is a large step for a dim texel, and every noisy
        // darker update taking it pulled the mean down.
        constexpr float kThreshold = 1.0f / 1024.0f;
        for (int c = 0; c < 3; ++c)
          lerp_delta[c] = std::min(std::max(kThreshold, std::abs(lerp_delta[c])), std::abs(delta[c])) *
                          (lerp_delta[c] > 0 ? 1.0f : lerp_delta[c] < 0 ? -1.0f : 0.0f);
      }
      texel = previous + lerp_delta;
    }
  update_border(map);
}

void blend_distance(OctahedralMap<glm::vec2>& map, const std::vector<RayRecord>& rays, const DdgiSettings& s,
                    float max_distance, float hysteresis) {
  const int n = map.interior;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const glm::vec3 texel_dir = texel_direction(x, y, n);
      glm::vec2 sum(0.0f);
      float weight_sum = 0.0f;
      for (const RayRecord& r : rays) {
        const float w = std::pow(std::max(0.0f, glm::dot(texel_dir, r.direction)), s.distance_exponent);
        const float d = std::min(std::abs(r.distance), max_distance);
        sum += w * glm::vec2(d, d * d);
        weight_sum += w;
      }
      if (weight_sum <= 0) continue;
      // The mean (RTXGI v1.2+ also halves distances here, which biases the
      // Chebyshev test towards occlusion; the mean is what the test needs).
      const glm::vec2 result = sum / weight_sum;
      glm::vec2& texel = map.at(x + 1, y + 1);
      texel = glm::mix(result, texel, hysteresis);
    }
  update_border(map);
}

}  // namespace transgi::ddgi
