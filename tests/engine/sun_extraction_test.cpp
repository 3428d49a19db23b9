// Known answers for the sun split: a disk of known radiance on a known sky
// comes out with the disk's irradiance, direction and size, and the residual
// is the sky; what the split moves from map to light adds back up.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "engine/scene/sun_extraction.h"

using namespace engine;
using scene::Environment;

namespace {

constexpr int kW = 512, kH = 256;

float pixel_solid_angle(int y) {
  return (math::kTwoPi / kW) * (math::kPi / kH) * std::sin(math::kPi * (static_cast<float>(y) + 0.5f) / kH);
}
glm::vec3 pixel_direction(int x, int y) {
  return Environment::uv_to_direction({(static_cast<float>(x) + 0.5f) / kW, (static_cast<float>(y) + 0.5f) / kH});
}

// Sky gradient plus a disk of radius `radius_deg` around `sun` (map-local).
struct SkyWithSun {
  image::ImageRGB image{kW, kH};
  glm::dvec3 disk_irradiance{0.0};  // exact: the disk pixels' excess x their solid angle
};
SkyWithSun sky_with_sun(glm::vec3 sun, float radius_deg, glm::vec3 disk, bool gradient = false) {
  SkyWithSun s;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const glm::vec3 d = pixel_direction(x, y);
      glm::vec3 c = gradient ? glm::vec3(0.3f, 0.5f, 0.9f) * (1.2f + 0.2f * d.y) : glm::vec3(0.5f, 0.6f, 0.8f);
      if (glm::dot(d, sun) > std::cos(glm::radians(radius_deg))) {
        c += disk;
        s.disk_irradiance += glm::dvec3(disk) * static_cast<double>(pixel_solid_angle(y));
      }
      s.image.at(x, y) = c;
    }
  return s;
}

// Irradiance on normal n from a map: sum over pixels of L cos+ dOmega.
glm::dvec3 map_irradiance(const Environment& env, glm::vec3 n) {
  glm::dvec3 e(0.0);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const float c = glm::dot(env.to_world(pixel_direction(x, y)), n);
      if (c > 0) e += glm::dvec3(env.strength() * env.image().at(x, y)) * static_cast<double>(c * pixel_solid_angle(y));
    }
  return e;
}

}  // namespace

TEST(SunExtraction, RecoversDiskIrradianceDirectionAndSize) {
  const glm::vec3 sun = glm::normalize(glm::vec3(0.6f, 0.5f, -0.3f));
  const glm::vec3 disk(5000.0f, 4500.0f, 4000.0f);
  const SkyWithSun sky = sky_with_sun(sun, 2.5f, disk);
  const Environment env(sky.image, 2.0f, glm::mat4(1.0f));
  const scene::SunSplit split = scene::split_sun(env);
  ASSERT_TRUE(split.sun.has_value()) << "a 2.5 degree disk 6000x the sky must be found";
  const scene::ExtractedSun& s = *split.sun;
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(s.irradiance[c], 2.0 * sky.disk_irradiance[c], 1e-4 * 2.0 * sky.disk_irradiance[c]) << "channel " << c;
  // The pixelised disk's mean direction is the centre to well under a pixel (0.7 degrees).
  EXPECT_LT(glm::degrees(std::acos(std::min(1.0f, glm::dot(s.direction, sun)))), 0.1f)
      << "expected " << sun.x << "," << sun.y << "," << sun.z << " got " << s.direction.x << "," << s.direction.y << ","
      << s.direction.z;
  const float analytic = math::kTwoPi * (1.0f - std::cos(glm::radians(2.5f)));
  EXPECT_NEAR(s.solid_angle, analytic, 0.05f * analytic) << "pixelised disk vs the analytic cone";
  EXPECT_NEAR(glm::degrees(s.angular_radius), 2.5f, 0.1f);
  float worst = 0;
  for (std::size_t i = 0; i < split.residual.image().pixels.size(); ++i)
    worst = std::max(worst, glm::length(split.residual.image().pixels[i] - glm::vec3(0.5f, 0.6f, 0.8f)));
  EXPECT_LT(worst, 1e-3f) << "the residual must be the sky alone";
}

TEST(SunExtraction, SunPlusResidualKeepsTheIrradiance) {
  // A sun on the u = 0 seam, a graded sky, a rotated map: whatever moves
  // from the map into the light, the irradiance on any plane the sun is well
  // above stays within the cone approximation of a small disk.
  const glm::vec3 sun = glm::normalize(glm::vec3(0.0f, 0.7f, -0.7f));  // u = 0 is local -z
  const SkyWithSun sky = sky_with_sun(sun, 3.0f, glm::vec3(900.0f), true);
  const glm::mat4 m = glm::mat4(glm::mat3(glm::vec3(0, 0, -1), glm::vec3(0, 1, 0), glm::vec3(1, 0, 0)));
  const Environment env(sky.image, 1.0f, m);
  const scene::SunSplit split = scene::split_sun(env);
  ASSERT_TRUE(split.sun.has_value());
  EXPECT_LT(glm::length(split.sun->direction - env.to_world(sun)), 2e-3f) << "the seam must not split the disk";
  math::Pcg32 rng(7, 1);
  for (int i = 0; i < 6; ++i) {
    glm::vec3 n = math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
    if (glm::dot(n, split.sun->direction) < 0.3f) n = glm::normalize(n + split.sun->direction);
    const glm::dvec3 original = map_irradiance(env, n);
    const glm::dvec3 parts =
        map_irradiance(split.residual, n) + glm::dvec3(split.sun->irradiance) * static_cast<double>(glm::dot(n, split.sun->direction));
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(parts[c], original[c], 2e-3 * original[c]) << "normal " << i << " channel " << c;
  }
}

TEST(SunExtraction, NoSunInASmoothSkyOrABroadGlow) {
  const SkyWithSun smooth = sky_with_sun(glm::vec3(0, 1, 0), 0.0f, glm::vec3(0.0f), true);
  const scene::SunSplit a = scene::split_sun(Environment(smooth.image, 1.0f, glm::mat4(1.0f)));
  EXPECT_FALSE(a.sun.has_value());
  EXPECT_EQ(a.residual.image().pixels, smooth.image.pixels);
  // A 15 degree bright patch is a glow, not a sun: the probes keep it.
  const SkyWithSun glow = sky_with_sun(glm::vec3(0, 1, 0), 15.0f, glm::vec3(500.0f));
  EXPECT_FALSE(scene::split_sun(Environment(glow.image, 1.0f, glm::mat4(1.0f))).sun.has_value());
  // Non-finite pixels never become a sun (and never crash the search).
  image::ImageRGB bad = smooth.image;
  bad.at(10, 10) = glm::vec3(std::numeric_limits<float>::infinity());
  bad.at(11, 10) = glm::vec3(std::nanf(""));
  EXPECT_FALSE(scene::split_sun(Environment(bad, 1.0f, glm::mat4(1.0f))).sun.has_value());
}
