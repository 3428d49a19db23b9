// Texture filtering by footprint (issue 14, item 4): the mip chain averages in
// the space a texture is read in, and ray cones give the level a rasteriser
// would pick. Known answers: a black and white checker of 1-texel squares
// averages to 0.5 in linear light; a 2 m quad mapped once by a 256-texel
// texture, seen head-on by a cone w wide, is read at log2(w / 2 * 256).
#include <gtest/gtest.h>

#include <cmath>

#include "engine/render/surface.h"
#include "engine/scene/procedural.h"
#include "engine/scene/texture.h"

using namespace engine;

namespace {
scene::Texture checker(int n, bool black_white = true) {
  scene::Texture t;
  t.width = t.height = n;
  t.rgba.resize(static_cast<std::size_t>(n) * n * 4);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const std::uint8_t v = ((x + y) & 1) ? 255 : (black_white ? 0 : 128);
      std::uint8_t* p = &t.rgba[(static_cast<std::size_t>(y) * n + x) * 4];
      p[0] = p[1] = p[2] = v;
      p[3] = 255;
    }
  return t;
}
}  // namespace

TEST(TextureLod, ACheckerAveragesToHalfInLinearLightAtEveryLevel) {
  scene::Texture t = checker(64);
  t.build_mips(true);
  ASSERT_EQ(t.mips.size(), 6u) << "64 -> 32, 16, 8, 4, 2, 1";
  EXPECT_EQ(t.mips.back().width, 1);
  for (float lod : {1.0f, 2.5f, 4.0f, 6.0f}) {
    const glm::vec4 c = t.sample({0.37f, 0.61f}, true, lod);
    EXPECT_NEAR(c.g, 0.5f, 0.005f) << "lod " << lod << ": expected 0.5 (linear), got " << c.g;
    EXPECT_NEAR(c.a, 1.0f, 1e-6f);
  }
  // Level 0 is the texture itself: a texel centre reads 0 or 1.
  EXPECT_NEAR(t.sample({0.5f / 64, 0.5f / 64}, true, 0.0f).g, 0.0f, 1e-6f);
  // Averaged as stored data (a roughness map), the same texture gives 0.5 of the code values.
  scene::Texture d = checker(64);
  d.build_mips(false);
  EXPECT_NEAR(d.sample({0.37f, 0.61f}, false, 3.0f).g, 0.5f, 0.005f);
  // Linear light, not code values: 0.5 encoded would read 0.214.
  scene::Texture grey = checker(64, false);
  grey.build_mips(true);
  const float expected = 0.5f * (1.0f + std::pow((128.0f / 255.0f + 0.055f) / 1.055f, 2.4f));
  EXPECT_NEAR(grey.sample({0.2f, 0.7f}, true, 3.0f).g, expected, 0.005f);
}

TEST(TextureLod, RayConeFootprintOnAQuadMatchesTheAnalyticLevel) {
  const scene::MeshAsset quad = scene::make_quad({1, 1});  // 2 m, UVs 0..1
  for (float w : {0.01f, 0.05f, 0.2f}) {
    const float f = render::uv_footprint(quad, 0, 1.0f, w, 1.0f);
    EXPECT_NEAR(f, w / 2, 1e-6f) << "cone " << w << " m over a 2 m quad";
    EXPECT_NEAR(render::texture_lod(f, 256, 256), std::log2(w / 2 * 256), 1e-4f);
    // Scaled by 2 into the world, the same cone covers half the UVs.
    EXPECT_NEAR(render::uv_footprint(quad, 0, 2.0f, w, 1.0f), w / 4, 1e-6f);
    // At 60 degrees from the normal it stretches by 1 / cos.
    EXPECT_NEAR(render::uv_footprint(quad, 0, 1.0f, w, 0.5f), w, 1e-6f);
  }
  scene::MeshAsset no_uvs = quad;
  no_uvs.uvs.clear();
  EXPECT_EQ(render::uv_footprint(no_uvs, 0, 1.0f, 0.1f, 1.0f), 0.0f);
}

// An alpha-tested texture (a leaf): one opaque green texel among three
// transparent white ones. Its mips average the colour weighted by alpha,
// so the leaf stays green at a distance, while alpha is the plain mean
// (a quarter covered). Without cut_out the white bleeds in: the plain
// mean. A block with no opaque texel keeps its plain mean. Known answers
// to the 8-bit sRGB encoding's rounding.
TEST(TextureLod, ACutOutsMipsAverageTheColourOfItsOpaqueTexels) {
  scene::Texture t;
  t.width = t.height = 4;
  t.rgba.assign(4 * 4 * 4, 255);  // white, opaque
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      std::uint8_t* p = &t.rgba[static_cast<std::size_t>(y * 4 + x) * 4];
      const bool leaf = x == 0 && y == 0;
      if (leaf) p[0] = p[2] = 0;  // (0, 255, 0)
      if (!leaf) p[3] = 0;        // transparent white elsewhere
    }
  scene::Texture plain = t;
  t.build_mips(true, true);
  plain.build_mips(true, false);
  const std::uint8_t* cut = t.mips[0].rgba.data();  // level 1, texel (0, 0): the leaf's block
  EXPECT_EQ(cut[0], 0);
  EXPECT_EQ(cut[1], 255);
  EXPECT_EQ(cut[2], 0);
  EXPECT_EQ(cut[3], 64);  // alpha 0.25
  const std::uint8_t* bled = plain.mips[0].rgba.data();
  EXPECT_GT(bled[0], 200) << "the plain mean takes three white texels in: 0.75 linear red";
  const std::uint8_t* empty = t.mips[0].rgba.data() + 4;  // level 1, texel (1, 0): no opaque texel
  EXPECT_EQ(empty[0], 255);
  EXPECT_EQ(empty[3], 0);
}

// The same at level 0: a bilinear lookup halfway between an opaque green
// texel and a transparent white one reads green (alpha 0.5) on a cut-out,
// the plain mean on any other texture.
TEST(TextureLod, ACutOutsBilinearLookupWeighsColourByAlpha) {
  scene::Texture t;
  t.width = 2;
  t.height = 1;
  t.wrap_s = t.wrap_t = scene::Wrap::ClampToEdge;
  t.rgba = {0, 255, 0, 255, 255, 255, 255, 0};
  scene::Texture plain = t;
  t.build_mips(true, true);
  plain.build_mips(true, false);
  const glm::vec4 cut = t.sample({0.5f, 0.5f}, true);
  EXPECT_NEAR(cut.r, 0.0f, 1e-6f);
  EXPECT_NEAR(cut.g, 1.0f, 1e-6f);
  EXPECT_NEAR(cut.a, 0.5f, 1e-6f);
  EXPECT_NEAR(plain.sample({0.5f, 0.5f}, true).r, 0.5f, 1e-6f);
}
