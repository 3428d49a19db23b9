#include <gtest/gtest.h>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfTiledOutputFile.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "engine/image/exr.h"
#include "engine/image/metrics.h"
#include "engine/image/tonemap.h"
#include "engine/math/rng.h"

namespace fs = std::filesystem;
using namespace engine::image;

namespace {

struct TempDir {
  fs::path path;
  TempDir() {
    path = fs::temp_directory_path() / ("image_test_" + std::to_string(::getpid()) + "_" +
                                        std::to_string(reinterpret_cast<std::uintptr_t>(this)));
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

void expect_error_mentions(const std::function<void()>& fn, const std::string& a, const std::string& b) {
  try {
    fn();
    FAIL() << "expected ImageError mentioning '" << a << "' and '" << b << "'";
  } catch (const ImageError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(a), std::string::npos) << msg;
    EXPECT_NE(msg.find(b), std::string::npos) << msg;
  }
}

ImageRGB ramp(int w, int h) {
  ImageRGB img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img.at(x, y) = {0.1f * static_cast<float>(x), 1000.0f * static_cast<float>(y), -2.5f};
  return img;
}

void write_raw(const fs::path& p, const std::string& bytes) {
  std::ofstream f(p, std::ios::binary);
  f << bytes;
}

}  // namespace

TEST(Exr, FloatRoundTripIsExact) {
  TempDir d;
  const ImageRGB img = ramp(7, 5);
  write_exr(d.path / "a.exr", img, ExrPixelType::Float);
  const ImageRGB back = read_exr(d.path / "a.exr");
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  for (std::size_t i = 0; i < img.size(); ++i) EXPECT_EQ(back.pixels[i], img.pixels[i]) << "pixel " << i;
}

TEST(Exr, HalfRoundTripWithinHalfPrecisionAndClampsToHalfRange) {
  TempDir d;
  ImageRGB img = ramp(4, 3);
  img.at(0, 0) = {1e6f, -1e6f, 0.333f};
  write_exr(d.path / "h.exr", img, ExrPixelType::Half);
  const ImageRGB back = read_exr(d.path / "h.exr");
  EXPECT_EQ(back.at(0, 0).r, 65504.0f) << "values above the half range clamp to its maximum";
  EXPECT_EQ(back.at(0, 0).g, -65504.0f);
  for (std::size_t i = 1; i < img.size(); ++i)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(back.pixels[i][c], img.pixels[i][c], std::abs(img.pixels[i][c]) * 1e-3f + 1e-4f) << i;
}

TEST(Exr, WritingNonFiniteIsRefusedAndKeepsTheOldFile) {
  TempDir d;
  write_exr(d.path / "keep.exr", ramp(2, 2));
  ImageRGB bad = ramp(2, 2);
  bad.at(1, 1).g = std::numeric_limits<float>::quiet_NaN();
  expect_error_mentions([&] { write_exr(d.path / "keep.exr", bad); }, "keep.exr", "pixel (1, 1)");
  EXPECT_EQ(read_exr(d.path / "keep.exr").at(1, 1), ramp(2, 2).at(1, 1));
}

TEST(Exr, RejectsMalformedFilesWithTheFileNamed) {
  TempDir d;
  expect_error_mentions([&] { read_exr(d.path / "missing.exr"); }, "missing.exr", "not found");
  expect_error_mentions([&] { read_exr(d.path); }, d.path.string(), "not a regular file");
  write_raw(d.path / "garbage.exr", "this is not an exr file at all");
  expect_error_mentions([&] { read_exr(d.path / "garbage.exr"); }, "garbage.exr", "magic");

  // A valid file cut in half.
  write_exr(d.path / "full.exr", ramp(64, 64));
  std::ifstream in(d.path / "full.exr", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  write_raw(d.path / "truncated.exr", bytes.substr(0, bytes.size() / 2));
  expect_error_mentions([&] { read_exr(d.path / "truncated.exr"); }, "truncated.exr", "malformed");

  // Version flags for tiled, deep and multi-part files are checked up front.
  for (auto [name, flag, word] : {std::tuple{"tiled.exr", 0x200, "tiled"}, std::tuple{"deep.exr", 0x800, "deep"},
                                  std::tuple{"multi.exr", 0x1000, "multi-part"}}) {
    std::string patched = bytes;
    patched[5] = static_cast<char>(patched[5] | (flag >> 8));
    write_raw(d.path / name, patched);
    expect_error_mentions([&, n = name] { read_exr(d.path / n); }, name, word);
  }
}

// The EXR fuzzer's 24-byte file: its one attribute declares 1,768,685,568
// bytes, which OpenEXR allocated before finding the file too short (250 MB,
// half a second). And a valid file whose first attribute's size is patched
// to run past the end. Both are refused before OpenEXR reads them.
TEST(Exr, AnAttributeLongerThanTheFileIsRefusedNamingIt) {
  TempDir d;
  const std::string fuzzed("v/1\x01\x02\0\0\0\x01t\0c\0\0\0lineOrder", 24);
  write_raw(d.path / "fuzzed.exr", fuzzed);
  expect_error_mentions([&] { read_exr(d.path / "fuzzed.exr"); }, "fuzzed.exr", "attribute '\\x01t' (c) declares 1768685568 bytes, but the file has 7 left");

  write_exr(d.path / "full.exr", ramp(8, 8));
  std::ifstream in(d.path / "full.exr", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The first attribute starts at byte 8: its name, its type, then 4 size bytes.
  const std::size_t name_end = bytes.find('\0', 8), type_end = bytes.find('\0', name_end + 1);
  const std::string first = bytes.substr(8, name_end - 8);
  bytes.replace(type_end + 1, 4, std::string("\xff\xff\xff\x7f", 4));
  write_raw(d.path / "patched.exr", bytes);
  expect_error_mentions([&] { read_exr(d.path / "patched.exr"); }, "patched.exr", "attribute '" + first + "'");
  expect_error_mentions([&] { read_exr(d.path / "patched.exr"); }, "patched.exr", "declares 2147483647 bytes");
}

TEST(Exr, RejectsARealTiledFile) {
  TempDir d;
  const fs::path p = d.path / "real_tiled.exr";
  Imf::Header header(16, 16);
  header.channels().insert("R", Imf::Channel(Imf::FLOAT));
  header.setTileDescription(Imf::TileDescription(8, 8, Imf::ONE_LEVEL));
  { Imf::TiledOutputFile out(p.c_str(), header); }
  expect_error_mentions([&] { read_exr(p); }, "real_tiled.exr", "tiled");
}

TEST(Exr, RejectsNonFinitePixelsOnRead) {
  TempDir d;
  const fs::path p = d.path / "nan.exr";
  std::vector<float> r(4, 1.0f), g(4, 1.0f), b(4, 1.0f);
  b[3] = std::numeric_limits<float>::infinity();
  Imf::Header header(2, 2);
  for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
  {
    Imf::OutputFile out(p.c_str(), header);
    Imf::FrameBuffer fb;
    fb.insert("R", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(r.data()), 4, 8));
    fb.insert("G", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(g.data()), 4, 8));
    fb.insert("B", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(b.data()), 4, 8));
    out.setFrameBuffer(fb);
    out.writePixels(2);
  }
  expect_error_mentions([&] { read_exr(p); }, "nan.exr", "pixel (1, 1)");
}

TEST(Exr, SizeCapIsEnforced) {
  TempDir d;
  write_exr(d.path / "big.exr", ramp(40, 30));
  ExrLimits limits;
  limits.max_dimension = 32;
  expect_error_mentions([&] { read_exr(d.path / "big.exr", limits); }, "big.exr", "size limit");
}

TEST(Tonemap, SrgbKnownValues) {
  EXPECT_NEAR(linear_to_srgb(0.0f), 0.0f, 1e-7f);
  EXPECT_NEAR(linear_to_srgb(1.0f), 1.0f, 1e-6f);
  EXPECT_NEAR(linear_to_srgb(0.18f), 0.46135613f, 1e-5f);  // middle grey
  EXPECT_NEAR(srgb_to_linear(linear_to_srgb(0.3f)), 0.3f, 1e-5f);
  ImageRGB img(1, 1, glm::vec3(0.25f));
  EXPECT_EQ(to_srgb8(img, 2.0f).pixels[0], 255) << "+2 stops turns 0.25 into 1.0";
}

// ---- metrics, against values computed by hand --------------------------------

TEST(Metrics, RmseL1AndRelMseHandComputed) {
  // 1x2 image pair. Clamped differences per channel: pixel 0 (0.5,0,0), pixel 1 (0,0,0.5)
  // (A's 2.0 clamps to 1.0 vs B's 1.0, and -1 clamps to 0 vs 0).
  ImageRGB a(2, 1), b(2, 1);
  a.pixels = {{1.0f, 0.5f, 0.0f}, {2.0f, -1.0f, 0.5f}};
  b.pixels = {{0.5f, 0.5f, 0.0f}, {1.0f, 0.0f, 0.0f}};
  // sum of squares = 0.25 + 0.25 = 0.5 over 6 values -> rmse = sqrt(1/12)
  EXPECT_NEAR(rmse_clamped(a, b), std::sqrt(1.0 / 12.0), 1e-12);
  EXPECT_NEAR(l1_clamped(a, b), 1.0 / 6.0, 1e-12);
  // relMSE (unclamped): (0.5^2/(0.25+0.01) + 0 + 0 + 1^2/(1+0.01) + 1^2/(0+0.01) + 0.5^2/(0+0.01)) / 6
  const double expected = (0.25 / 0.26 + 1.0 / 1.01 + 1.0 / 0.01 + 0.25 / 0.01) / 6.0;
  EXPECT_NEAR(relmse(a, b), expected, 1e-9);
}

TEST(Metrics, MeanRatioPerChannelIsEachChannelsSumOverTheReferences) {
  // Unclamped: a's (1.5, -0.25, 0.25) and b's (0.75, 0.25, 0) on every pixel -> 2, -1, and 0 where b has none.
  ImageRGB a(11, 11), b(11, 11);
  for (std::size_t i = 0; i < a.size(); ++i) {
    a.pixels[i] = {1.5f, -0.25f, 0.25f};
    b.pixels[i] = {0.75f, 0.25f, 0.0f};
  }
  const ErrorMetrics m = compare_images(a, b);
  EXPECT_NEAR(m.mean_ratio_rgb.r, 2.0, 1e-9);
  EXPECT_NEAR(m.mean_ratio_rgb.g, -1.0, 1e-9);
  EXPECT_EQ(m.mean_ratio_rgb.b, 0.0);
}

TEST(Metrics, SsimOfIdenticalImagesIsOne) {
  ImageRGB a(16, 13);
  for (std::size_t i = 0; i < a.size(); ++i) a.pixels[i] = glm::vec3(static_cast<float>(i % 7) / 7.0f);
  EXPECT_NEAR(ssim_luminance(a, a), 1.0, 1e-12);
}

TEST(Metrics, SsimOfTwoConstantImagesIsTheLuminanceTerm) {
  // No variance: SSIM = (2 mu_a mu_b + C1) / (mu_a^2 + mu_b^2 + C1).
  const ImageRGB a(12, 12, glm::vec3(0.2f)), b(12, 12, glm::vec3(0.6f));
  const double c1 = 1e-4, ma = 0.2, mb = 0.6;
  const double expected = (2 * ma * mb + c1) / (ma * ma + mb * mb + c1);
  EXPECT_NEAR(ssim_luminance(a, b), expected, 1e-6);
}

TEST(Metrics, SsimMatchesADirectSingleWindowComputation) {
  // An 11x11 pair has exactly one window: compute it with explicit weights.
  ImageRGB a(11, 11), b(11, 11);
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 11; ++x) {
      a.at(x, y) = glm::vec3(static_cast<float>((x * 3 + y * 5) % 11) / 10.0f);
      b.at(x, y) = glm::vec3(static_cast<float>((x * 7 + y) % 11) / 12.0f);
    }
  double w[11][11], wsum = 0;
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 11; ++x) wsum += (w[y][x] = std::exp(-((x - 5) * (x - 5) + (y - 5) * (y - 5)) / 4.5));
  double ma = 0, mb = 0, saa = 0, sbb = 0, sab = 0;
  for (int y = 0; y < 11; ++y)
    for (int x = 0; x < 11; ++x) {
      const double k = w[y][x] / wsum, ya = a.at(x, y).r, yb = b.at(x, y).r;  // grey: Y = value
      ma += k * ya;
      mb += k * yb;
      saa += k * ya * ya;
      sbb += k * yb * yb;
      sab += k * ya * yb;
    }
  const double c1 = 1e-4, c2 = 9e-4;
  const double expected = ((2 * ma * mb + c1) * (2 * (sab - ma * mb) + c2)) /
                          ((ma * ma + mb * mb + c1) * ((saa - ma * ma) + (sbb - mb * mb) + c2));
  EXPECT_NEAR(ssim_luminance(a, b), expected, 1e-6) << "expected " << expected;
}

TEST(Metrics, SizeMismatchIsAnError) {
  EXPECT_THROW(compare_images(ImageRGB(12, 12), ImageRGB(12, 13)), ImageError);
  EXPECT_THROW(ssim_luminance(ImageRGB(5, 5), ImageRGB(5, 5)), ImageError);
}

TEST(Metrics, HeatmapScalesToThe99thPercentile) {
  ImageRGB a(10, 10), b(10, 10);
  for (std::size_t i = 0; i < a.size(); ++i) a.pixels[i] = glm::vec3(static_cast<float>(i) / 100.0f);
  double used = 0;
  const Rgb8Image h = error_heatmap(a, b, 0, &used);
  EXPECT_NEAR(used, 0.98, 1e-6);
  EXPECT_EQ(h.pixels[0], 0);                  // zero error is black
  EXPECT_EQ(h.pixels[99 * 3 + 2], 255);       // the largest error saturates to white
}

TEST(Metrics, TopErrorShareIsTheWorstPixelsShareOfTheSquaredError) {
  // 100 pixels: 99 off by 0.1 in every channel, one off by 0.5: squared
  // errors 99 x 0.03 and 1 x 0.75, so the worst 1 % holds 0.75 / 3.72.
  engine::image::ImageRGB a(10, 10), b(10, 10);
  for (auto& p : b.pixels) p = glm::vec3(0.1f);
  b.pixels[37] = glm::vec3(0.5f);
  EXPECT_NEAR(engine::image::top_error_share(a, b, 0.01), 0.75 / 3.72, 1e-6);
  EXPECT_NEAR(engine::image::top_error_share(a, b, 1.0), 1.0, 1e-12);
  EXPECT_EQ(engine::image::top_error_share(a, a, 0.5), 0.0) << "no error, no share";
}

TEST(Metrics, EdgeBandHoldsThePixelsNearAStepAndItsRmseOnlyThose) {
  // A step from 0.1 to 0.8 between columns 9 and 10 of a 24x8 image: the 3x3
  // box mean blurs it over columns 9-10 and their neighbours, so with radius
  // 2 the band is columns 6-13.
  ImageRGB guide(24, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 24; ++x) guide.at(x, y) = glm::vec3(x < 10 ? 0.1f : 0.8f);
  const auto band = edge_band(guide, 2);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 24; ++x)
      EXPECT_EQ(band[static_cast<std::size_t>(y) * 24 + x], x >= 6 && x <= 13 ? 1 : 0) << "pixel " << x << ", " << y;
  ImageRGB a = guide, b = guide;
  a.at(8, 3) += glm::vec3(0.3f);   // in the band
  a.at(20, 3) += glm::vec3(0.9f);  // outside it
  EXPECT_NEAR(rmse_clamped_in(a, b, band), std::sqrt(0.09 / (8.0 * 8.0)), 1e-6);
  const ImageRGB flat(24, 8);
  const auto none = edge_band(flat, 2);
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
  EXPECT_EQ(rmse_clamped_in(a, b, none), 0.0);
}

TEST(Metrics, ColourMetricsMeasureHueShiftAndDetail) {
  // B: an orange/blue checker; A: the same light in grey (luminance kept
  // per pixel does not matter to chroma: c = rgb / sum).
  ImageRGB a(8, 8), b(8, 8);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      b.at(x, y) = ((x + y) & 1) ? glm::vec3(0.6f, 0.3f, 0.1f) : glm::vec3(0.1f, 0.2f, 0.7f);
      a.at(x, y) = glm::vec3(0.3f);
    }
  const ColourMetrics same = compare_colour(b, b);
  EXPECT_EQ(same.pixels, 64u);
  EXPECT_DOUBLE_EQ(same.chroma_error, 0.0);
  EXPECT_DOUBLE_EQ(same.detail_a, same.detail_b);
  EXPECT_GT(same.detail_b, 0.1) << "a checker varies from pixel to pixel";
  const ColourMetrics grey = compare_colour(a, b);
  // Orange c = (0.6, 0.3, 0.1), blue c = (0.1, 0.2, 0.7): |c - 1/3| sums 0.533 and 0.733.
  EXPECT_NEAR(grey.chroma_error, 0.5 * (0.5333333 + 0.7333333), 1e-5);
  EXPECT_DOUBLE_EQ(grey.detail_a, 0.0) << "flat grey has no detail";
}

TEST(Metrics, TextureGainSeesTheAlbedosContrastThroughTheReferencesNoise) {
  // A 64 x 64 texture L (albedo 0.3-0.7, seeded), lit by 1: the reference B
  // is L plus independent noise of 0.1, as a path tracer's; A carries the
  // texture exactly, H at half its contrast around the mean. The gain must
  // find 1 and about 0.5 (H's relative detail is half of L's only to first
  // order: tolerance 0.05), where the noise-biased detail ratio says A has
  // too little texture.
  const int n = 64;
  ImageRGB l(n, n), a(n, n), b(n, n), h(n, n), mask(n, n);
  engine::math::Pcg32 rng = engine::math::make_rng(11, 0, 0);
  double mean = 0;
  for (auto& p : l.pixels) {
    p = glm::vec3(0.3f + 0.4f * rng.next_float());
    mean += p.g / (n * n);
  }
  for (std::size_t i = 0; i < l.size(); ++i) {
    a.pixels[i] = l.pixels[i];
    b.pixels[i] = l.pixels[i] + glm::vec3(0.2f * (rng.next_float() - 0.5f) * std::sqrt(3.0f));
    h.pixels[i] = glm::vec3(static_cast<float>(mean)) + 0.5f * (l.pixels[i] - glm::vec3(static_cast<float>(mean)));
    mask.pixels[i] = glm::vec3(i % n < n / 2 ? 1.0f : 0.0f);  // the left half is "textured"
  }
  const ColourMetrics exact = compare_colour(a, b, nullptr, &l), halved = compare_colour(h, b, nullptr, &l);
  EXPECT_NEAR(exact.texture_gain, 1.0, 0.05);
  EXPECT_NEAR(halved.texture_gain, 0.5, 0.05);
  EXPECT_GT(exact.texture_correlation, 0.5);
  EXPECT_LT(exact.detail_a / exact.detail_b, 0.9) << "the reference's noise inflates its detail, or this test shows nothing";
  EXPECT_DOUBLE_EQ(compare_colour(b, b, nullptr, &l).texture_gain, 1.0);
  // The mask: only pixels whose 3 x 3 neighbourhood lies in the left half
  // (columns 0-30) count, all rows.
  const ColourMetrics left = compare_colour(a, b, &mask, &l);
  EXPECT_EQ(left.pixels, static_cast<std::size_t>(31 * n));
  EXPECT_EQ(compare_colour(a, b).texture_gain, 0.0) << "no albedo, no gain";
}

TEST(Metrics, SpeckleFractionCountsIsolatedPixelsNotEdgesOrGradients) {
  using namespace engine::image;
  ImageRGB img(20, 10);
  for (int y = 0; y < 10; ++y)
    for (int x = 0; x < 20; ++x) img.at(x, y) = glm::vec3(x < 10 ? 0.05f : 0.8f) * (1.0f + 0.01f * static_cast<float>(y));
  EXPECT_DOUBLE_EQ(speckle_fraction(img), 0.0) << "a hard edge is not a speckle";
  img.at(3, 4) = glm::vec3(1.0f);     // white on the dark side
  img.at(15, 5) = glm::vec3(0.0f);    // black on the bright side
  img.at(0, 0) = glm::vec3(0.0f, 0.0f, 1.0f);  // a blue corner pixel: one channel is enough
  EXPECT_DOUBLE_EQ(speckle_fraction(img), 3.0 / 200.0);
  // 60 levels is the threshold: a step of 50/255 (displayed) is not one.
  ImageRGB soft(5, 5, glm::vec3(srgb_to_linear(0.5f)));
  soft.at(2, 2) = glm::vec3(srgb_to_linear(0.5f + 50.0f / 255.0f));
  EXPECT_DOUBLE_EQ(speckle_fraction(soft), 0.0);
  soft.at(2, 2) = glm::vec3(srgb_to_linear(0.5f + 70.0f / 255.0f));
  EXPECT_DOUBLE_EQ(speckle_fraction(soft), 1.0 / 25.0);
}

// Block means: a 5 x 3 image in 2 x 2 blocks gives 3 x 2 blocks, the right
// column and bottom row averaging the pixels they hold; alternating noise of
// +-1 around a level vanishes in every full block; n = 1 is a copy; n < 1 is
// refused.
TEST(Metrics, BoxDownsampleAveragesBlocksAndPartialEdges) {
  ImageRGB img(5, 3);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) img.at(x, y) = glm::vec3(static_cast<float>(y * 5 + x), 10.0f + ((x + y) % 2 ? 1.0f : -1.0f), 1.0f);
  const ImageRGB d = box_downsample(img, 2);
  ASSERT_EQ(d.width, 3);
  ASSERT_EQ(d.height, 2);
  EXPECT_FLOAT_EQ(d.at(0, 0).r, (0 + 1 + 5 + 6) / 4.0f);
  EXPECT_FLOAT_EQ(d.at(2, 0).r, (4 + 9) / 2.0f);  // the right column: one pixel wide
  EXPECT_FLOAT_EQ(d.at(1, 1).r, (12 + 13) / 2.0f);  // the bottom row: one pixel high
  EXPECT_FLOAT_EQ(d.at(2, 1).r, 14.0f);
  EXPECT_FLOAT_EQ(d.at(0, 0).g, 10.0f) << "the +-1 noise averages out in a full block";
  EXPECT_FLOAT_EQ(d.at(1, 0).g, 10.0f);
  EXPECT_FLOAT_EQ(d.at(2, 1).b, 1.0f);
  const ImageRGB same = box_downsample(img, 1);
  EXPECT_EQ(same.pixels, img.pixels);
  EXPECT_THROW((void)box_downsample(img, 0), std::invalid_argument);
}
