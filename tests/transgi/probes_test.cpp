// Probe building blocks against known answers: exact projection of a
// constant map, the window reducing measured ringing, the trilinear cage,
// radiance sharing placing points in the right texels, the depth guard
// stopping a leak through a wall, and unsampled texels never read as black.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/math/rng.h"
#include "engine/math/sampling.h"
#include "probes/probe_map.h"
#include "probes/radiance_sharing.h"

using namespace transgi::probes;

TEST(RadianceMap, SolidAnglesSumToTheSphereAndTexelsRoundTrip) {
  const MapLayout m;
  double total = 0;
  for (int t = 0; t < m.texel_count(); ++t) {
    total += m.solid_angle(t);
    ASSERT_EQ(m.texel_of(m.direction_of(t)), t) << "texel " << t;
  }
  EXPECT_NEAR(total, 4 * engine::math::kPi, 1e-9);
}

TEST(RadianceMap, FastAtan2KeepsTheSignedZeroConventions) {
  for (float y : {0.0f, -0.0f, 1.0f, -1.0f})
    for (float x : {0.0f, -0.0f, 1.0f, -1.0f}) {
      const float expected = std::atan2(y, x), got = fast_atan2(y, x);
      EXPECT_NEAR(got, expected, 2e-5f) << "atan2(" << y << ", " << x << ")";  // the polynomial's bound
      EXPECT_EQ(std::signbit(got), std::signbit(expected)) << "atan2(" << y << ", " << x << ")";
    }
}

TEST(RadianceMap, FastTexelLookupMatchesTheReferenceAwayFromBorders) {
  // texel_of uses polynomial atan2/acos; texel_of_reference the library
  // ones. They may disagree only for directions within 1e-4 rad of a texel
  // border; the polynomials themselves stay within 2e-5 rad.
  const MapLayout m;
  engine::math::Pcg32 rng(5, 3);
  int disagree = 0, near_border = 0;
  double worst_atan = 0, worst_acos = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    glm::vec3 d = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
    if (i < 16) d = glm::vec3(i & 1 ? -1.0f : 1.0f, 0, 0) * (i < 8 ? 1.0f : 0.0f) + glm::vec3(0, i >= 8 ? (i & 1 ? -1.0f : 1.0f) : 0.0f, 0);
    // Modulo 2 pi: at the branch cut +pi and -pi are the same angle (and texel).
    worst_atan = std::max(worst_atan, std::abs(std::remainder(static_cast<double>(fast_atan2(d.x, -d.z)) - std::atan2(d.x, -d.z), 2 * M_PI)));
    worst_acos = std::max(worst_acos, static_cast<double>(std::abs(fast_acos(d.y) - std::acos(std::clamp(d.y, -1.0f, 1.0f)))));
    const int fast = m.texel_of(d), ref = m.texel_of_reference(d);
    if (fast == ref) continue;
    ++disagree;
    const float u = (std::atan2(d.x, -d.z) / engine::math::kTwoPi + 1.0f) * m.width, v = std::acos(d.y) / engine::math::kPi * m.height;
    const float du = std::abs(u - std::round(u)) * engine::math::kTwoPi / m.width, dv = std::abs(v - std::round(v)) * engine::math::kPi / m.height;
    near_border += std::min(du, dv) < 1e-4f;
  }
  EXPECT_LT(worst_atan, 2e-5) << "polynomial atan2 error";
  EXPECT_LT(worst_acos, 2e-5) << "polynomial acos error";
  EXPECT_EQ(disagree, near_border) << "every disagreement must be within 1e-4 rad of a border; " << disagree << " of " << n
                                   << " differ, " << near_border << " of them at a border";
  EXPECT_LT(disagree, n / 1000);
}

TEST(RadianceMap, VectorisedProjectionKeepsBandZeroExactOnARandomMap) {
  // Band 0's texel integral is Y00 x the texel's solid angle exactly, so for
  // any map out[0] = Y00 x sum(L x omega): the float row sums of the
  // vectorised projection must hold that to float rounding (the old scalar
  // loop summed in double).
  const MapLayout m;
  const MapProjector proj(m);
  engine::math::Pcg32 rng(11, 4);
  std::vector<glm::vec3> L(static_cast<std::size_t>(m.texel_count()));
  double want[3] = {0, 0, 0};
  const double y00 = 0.5 / std::sqrt(M_PI);
  for (int t = 0; t < m.texel_count(); ++t) {
    const float s = rng.next_float() < 0.1f ? 50.0f : 1.0f;  // a few bright texels, as a window gives
    L[static_cast<std::size_t>(t)] = s * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
    for (int c = 0; c < 3; ++c) want[c] += y00 * L[static_cast<std::size_t>(t)][c] * m.solid_angle(t);
  }
  float out[75];
  proj.project(L.data(), out);
  for (int c = 0; c < 3; ++c)
    EXPECT_NEAR(out[c * 25], want[c], 2e-5 * want[c]) << "channel " << c << ": expected " << want[c] << ", got " << out[c * 25];
}

TEST(RadianceMap, ConstantMapProjectsToBandZeroOnly) {
  const MapLayout m;
  const MapProjector proj(m);
  const std::vector<glm::vec3> L(static_cast<std::size_t>(m.texel_count()), glm::vec3(2.0f));
  float c[75];
  proj.project(L.data(), c);
  EXPECT_NEAR(c[0], 2 * 2 * std::sqrt(engine::math::kPi), 1e-4) << "2 x 2 sqrt(pi)";
  for (int k = 1; k < 25; ++k) EXPECT_NEAR(c[k], 0.0f, 2e-4f) << "coefficient " << k;
  // 24 residuals below 2e-4 (4x4 sub-samples per texel) add up at the pole.
  EXPECT_NEAR(evaluate_clamped(c, glm::vec3(0, 1, 0)).g, 2.0f, 1e-3f);
}

TEST(RadianceMap, HanningWindowReducesRingingOfAStep) {
  // Upper hemisphere 1, lower 0: degree-4 SH overshoots and goes negative
  // near the edge. The window must shrink both, at the cost of a softer edge.
  const MapLayout m;
  const MapProjector proj(m);
  std::vector<glm::vec3> L(static_cast<std::size_t>(m.texel_count()));
  for (int t = 0; t < m.texel_count(); ++t) L[static_cast<std::size_t>(t)] = glm::vec3(m.direction_of(t).y > 0 ? 1.0f : 0.0f);
  float raw[75], windowed[75];
  proj.project(L.data(), raw);
  std::copy(raw, raw + 75, windowed);
  apply_hanning_window(windowed);
  auto extremes = [&](const float* c) {
    float lo = 1e9f, hi = -1e9f;
    for (int i = 0; i <= 180; ++i) {
      const float th = engine::math::kPi * i / 180.0f;
      const glm::vec3 d(std::sin(th), std::cos(th), 0);
      const auto b = engine::math::sh_eval(d);
      float v = 0;
      for (int k = 0; k < 25; ++k) v += c[k] * b[static_cast<std::size_t>(k)];
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    return std::pair(lo, hi);
  };
  const auto [raw_lo, raw_hi] = extremes(raw);
  const auto [win_lo, win_hi] = extremes(windowed);
  EXPECT_LT(raw_lo, -0.02f) << "an unwindowed step rings below zero";
  EXPECT_GT(win_lo, raw_lo) << "the window reduces the undershoot";
  EXPECT_LT(win_hi - 1.0f, raw_hi - 1.0f) << "and the overshoot";
}

TEST(ProbeGrid, FlatGridsHaveFiniteCages) {
  // One probe thick along y and z: no spacing there, still finite weights.
  const ProbeGrid g{{0, 0, 0}, {1, 0, 0}, {2, 1, 1}};
  const auto c = g.cage({0.25f, 0.3f, -0.2f});
  float sum = 0;
  for (float w : c.weights) {
    ASSERT_TRUE(std::isfinite(w));
    sum += w;
  }
  EXPECT_NEAR(sum, 1.0f, 1e-6f);
  EXPECT_EQ(g.min_spacing(), 1.0f);
}

TEST(ProbeGrid, CageWeightsReproduceLinearFunctions) {
  ProbeGrid g{{-1, 0, -2}, {3, 2, 2}, {5, 3, 4}};
  engine::math::Pcg32 rng(1, 1);
  for (int i = 0; i < 100; ++i) {
    const glm::vec3 p = g.min + (g.max - g.min) * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
    const auto c = g.cage(p);
    float wsum = 0;
    glm::vec3 interp(0.0f);
    for (int k = 0; k < 8; ++k) {
      wsum += c.weights[static_cast<std::size_t>(k)];
      interp += c.weights[static_cast<std::size_t>(k)] * g.position(c.probes[static_cast<std::size_t>(k)]);
      ASSERT_EQ(c.positions[static_cast<std::size_t>(k)], g.position(c.probes[static_cast<std::size_t>(k)])) << "corner " << k;
    }
    EXPECT_NEAR(wsum, 1.0f, 1e-5f);
    EXPECT_NEAR(glm::length(interp - p), 0.0f, 1e-4f) << "trilinear weights reproduce the position itself";
  }
}

TEST(ProbeGrid, CagePositionsIncludeRelocationOffsets) {
  ProbeGrid g{{-1, 0, -2}, {3, 2, 2}, {5, 3, 4}};
  g.offsets.resize(static_cast<std::size_t>(g.count()));
  for (int i = 0; i < g.count(); ++i) g.offsets[static_cast<std::size_t>(i)] = glm::vec3(0.01f * i, -0.02f * (i % 3), 0.03f);
  const auto c = g.cage({0.3f, 1.1f, 0.7f});
  for (std::size_t k = 0; k < 8; ++k) {
    EXPECT_EQ(c.positions[k], g.position(c.probes[k])) << "corner " << k;
    EXPECT_NE(c.positions[k], g.grid_point(c.probes[k])) << "corner " << k << ": the offset was left out";
  }
}

TEST(RadianceSharing, NeighbourPointsLandInTheDirectionFromTheTargetProbe) {
  const ProbeGrid g{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  const MapLayout m{32, 16};
  std::vector<std::vector<ShadedPoint>> pts(static_cast<std::size_t>(g.count()));
  // Probe 7 at (1,1,1) sees a point at (0.5, 1.5, 0.5) with radiance 3.
  const glm::vec3 q = g.position(7), point(0.5f, 1.5f, 0.5f);
  pts[7].push_back({point, glm::vec3(3.0f), glm::normalize(point - q), glm::length(point - q)});
  std::vector<FrameSamples> out;
  const auto stats = rasterize_shared(g, m, pts, {}, {}, out);
  EXPECT_EQ(stats.accepted, 8u) << "every probe of a 2x2x2 grid neighbours probe 7";
  for (int p = 0; p < g.count(); ++p) {
    const int t = m.texel_of(glm::normalize(point - g.position(p)));
    EXPECT_EQ(out[static_cast<std::size_t>(p)].count[static_cast<std::size_t>(t)], 1.0f) << "probe " << p;
    EXPECT_EQ(out[static_cast<std::size_t>(p)].sum[static_cast<std::size_t>(t)], glm::vec3(3.0f));
  }
}

TEST(RadianceSharing, DepthGuardStopsALeakThroughAWall) {
  // Two probes along x; a wall at x = 0.5 between them. Probe 0's own ray
  // towards +x hits the wall at distance 0.5. Probe 1 (beyond the wall) sees
  // a bright point at x = 2 in the same direction: sharing it with probe 0
  // would leak light through the wall.
  const ProbeGrid g{{0, 0, 0}, {1, 0, 0}, {2, 1, 1}};
  const MapLayout m{32, 16};
  std::vector<std::vector<ShadedPoint>> pts(2);
  pts[0].push_back({{0.5f, 0, 0}, glm::vec3(0.1f), {1, 0, 0}, 0.5f});
  pts[1].push_back({{2.0f, 0, 0}, glm::vec3(50.0f), {1, 0, 0}, 1.0f});
  std::vector<ProbeMapState> states(2);
  for (auto& s : states) s.reset(m.texel_count());
  update_own_depth(states[0], m, pts[0], {});
  update_own_depth(states[1], m, pts[1], {});
  const std::vector<const DepthMap*> depth = {&states[0].depth, &states[1].depth};
  const int t = m.texel_of({1, 0, 0});

  std::vector<FrameSamples> guarded, faithful;
  const auto gs = rasterize_shared(g, m, pts, depth, {.mode = SharingMode::DepthGuard}, guarded);
  rasterize_shared(g, m, pts, depth, {.mode = SharingMode::PaperFaithful}, faithful);
  // Probe 1's point beyond the wall for probe 0, and probe 0's point on the
  // wall for probe 1, whose own rays towards -x found nothing.
  EXPECT_EQ(gs.rejected_by_guard, 2u);
  EXPECT_EQ(guarded[0].sum[static_cast<std::size_t>(t)], glm::vec3(0.1f)) << "only the wall's own radiance";
  EXPECT_EQ(faithful[0].sum[static_cast<std::size_t>(t)], glm::vec3(50.1f)) << "the paper-faithful mode leaks";
}

TEST(RadianceSharing, ATexelWithoutOwnHitsTakesNoNeighbourPoint) {
  // Probe 0 stands under a table top (y = 0.3, wide): its rays up meet the
  // table's underside, except in the texel straight up (a polar texel of
  // the lat-long map, which its rays may not reach for frames). Probe 1,
  // beside the table, sees the bright ceiling (y = 2.5) right above probe 0.
  // Without an own hit there the guard cannot compare distances: sharing
  // the ceiling's point would light probe 0's zenith through the table.
  const ProbeGrid g{{0, 0, 0}, {1, 0, 0}, {2, 1, 1}};
  const MapLayout m{32, 16};
  const glm::vec3 ceiling{0.0f, 2.5f, 0.0f};
  const glm::vec3 from_1 = glm::normalize(ceiling - g.position(1));
  const int zenith = m.texel_of({0, 1, 0});
  ASSERT_EQ(m.texel_of(glm::normalize(ceiling - g.position(0))), zenith);
  std::vector<std::vector<ShadedPoint>> pts(2);
  pts[1].push_back({ceiling, glm::vec3(20.0f), from_1, glm::length(ceiling - g.position(1)), -from_1});
  std::vector<ProbeMapState> states(2);
  for (auto& st : states) st.reset(m.texel_count());
  const std::vector<const DepthMap*> depth = {&states[0].depth, &states[1].depth};
  std::vector<FrameSamples> out;

  ASSERT_TRUE(std::isnan(states[0].depth.mean(static_cast<std::size_t>(zenith))));
  auto stats = rasterize_shared(g, m, pts, depth, {}, out);
  EXPECT_EQ(out[0].count[static_cast<std::size_t>(zenith)], 0.0f) << "no own hit: the ceiling's point is not taken";
  EXPECT_EQ(stats.rejected_by_guard, 1u);

  // An escaped own ray leaves the texel without a hit too: still rejected.
  pts[0] = {{glm::vec3(0.0f), glm::vec3(0.0f), {0, 1, 0}, std::numeric_limits<float>::infinity()}};
  update_own_depth(states[0], m, pts[0], {});
  rasterize_shared(g, m, pts, depth, {}, out);
  EXPECT_EQ(out[0].count[static_cast<std::size_t>(zenith)], 1.0f) << "only the escaped ray's zero sample";
  EXPECT_EQ(out[0].sum[static_cast<std::size_t>(zenith)], glm::vec3(0.0f));

  // Once probe 0's own ray there hits the ceiling (no table this time), the
  // point is taken.
  states[0].reset(m.texel_count());
  pts[0] = {{ceiling, glm::vec3(20.0f), {0, 1, 0}, 2.5f, {0, -1, 0}}};
  update_own_depth(states[0], m, pts[0], {});
  stats = rasterize_shared(g, m, pts, depth, {}, out);
  EXPECT_EQ(out[0].count[static_cast<std::size_t>(zenith)], 2.0f) << "its own hit and the neighbour's point";
  EXPECT_EQ(out[0].sum[static_cast<std::size_t>(zenith)], glm::vec3(40.0f));
}

TEST(RadianceSharing, ACoarseTexelOverTwoDepthsKeepsTheFarSurfacesPoints) {
  // Probe 0's texel towards +x holds own hits at 1 and 3 (a chair before a
  // wall): depth mean 2, sd 1. A neighbour's point on the wall (distance 2.9
  // from probe 0) belongs in that texel; one at 4 lies behind the wall.
  // Against the mean alone (spread 0) the wall's point was dropped and the
  // texel took the chair's light for the whole of it.
  const ProbeGrid g{{0, 0, 0}, {0.5f, 0, 0}, {2, 1, 1}};
  const MapLayout m{32, 16};
  const int t = m.texel_of({1, 0, 0});
  std::vector<ProbeMapState> states(2);
  for (auto& s : states) s.reset(m.texel_count());
  states[0].depth.set(static_cast<std::size_t>(t), 2.0f, 1.0f);
  const std::vector<const DepthMap*> depth = {&states[0].depth, &states[1].depth};
  std::vector<std::vector<ShadedPoint>> pts(2);
  pts[1].push_back({{2.9f, 0, 0}, glm::vec3(1.0f), {1, 0, 0}, 2.4f, {-1, 0, 0}});
  pts[1].push_back({{4.0f, 0, 0}, glm::vec3(100.0f), {1, 0, 0}, 3.5f, {-1, 0, 0}});
  std::vector<FrameSamples> out;
  // Threshold 2 x 1.1 + 0.05 (x the depth unit, 1 here) + k x 1: 2.25 at k = 0, 3.25 at k = 1.
  SharingSettings s;
  ASSERT_EQ(s.spread_tolerance, 1.0f);
  rasterize_shared(g, m, pts, depth, s, out);
  EXPECT_EQ(out[0].count[static_cast<std::size_t>(t)], 1.0f) << "the wall's point only";
  EXPECT_EQ(out[0].sum[static_cast<std::size_t>(t)], glm::vec3(1.0f));
  s.spread_tolerance = 0;
  rasterize_shared(g, m, pts, depth, s, out);
  EXPECT_EQ(out[0].count[static_cast<std::size_t>(t)], 0.0f) << "against the mean alone both are dropped";
}

// rasterize_shared computes each neighbour's point geometry as vectors; the
// reference one point at a time. Same arithmetic, no contraction: every
// texel's sum and count and both counters are the same bits, with escaped
// rays, points seen from behind and points the depth guard rejects.
TEST(RadianceSharing, VectorisedGeometryEqualsTheReferenceBitForBit) {
  const ProbeGrid g{{-1, 0, -1}, {1, 2, 1}, {3, 3, 3}};
  const MapLayout m{50, 25};
  engine::math::Pcg32 rng(6, 2);
  std::vector<std::vector<ShadedPoint>> pts(static_cast<std::size_t>(g.count()));
  std::vector<ProbeMapState> states(static_cast<std::size_t>(g.count()));
  for (int q = 0; q < g.count(); ++q) {
    for (int r = 0; r < 100; ++r) {
      const glm::vec3 dir = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
      const float t = rng.next_float() < 0.1f ? INFINITY : 0.1f + 1.5f * rng.next_float();
      const glm::vec3 normal = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
      const glm::vec3 pos = std::isfinite(t) ? g.position(q) + dir * t : glm::vec3(0.0f);
      pts[static_cast<std::size_t>(q)].push_back({pos, glm::vec3(rng.next_float(), rng.next_float(), 1.0f), dir, t, normal});
    }
    states[static_cast<std::size_t>(q)].reset(m.texel_count());
    update_own_depth(states[static_cast<std::size_t>(q)], m, pts[static_cast<std::size_t>(q)], {});
  }
  std::vector<const DepthMap*> depth;
  for (const auto& st : states) depth.push_back(&st.depth);
  std::vector<std::uint8_t> targets(static_cast<std::size_t>(g.count()), 1);
  targets[4] = 0;  // a budgeted frame skips some probes
  std::vector<FrameSamples> fast, ref;
  const SharingStats a = rasterize_shared(g, m, pts, depth, {}, fast, targets);
  const SharingStats b = rasterize_shared_reference(g, m, pts, depth, {}, ref, targets);
  EXPECT_EQ(a.accepted, b.accepted);
  EXPECT_EQ(a.rejected_by_guard, b.rejected_by_guard);
  EXPECT_GT(b.rejected_by_guard, 0u) << "the guards must reject something, or that path went untested";
  ASSERT_EQ(fast.size(), ref.size());
  for (std::size_t q = 0; q < ref.size(); ++q) {
    ASSERT_EQ(fast[q].count, ref[q].count) << "probe " << q;
    ASSERT_EQ(fast[q].sum, ref[q].sum) << "probe " << q;
  }
}

TEST(ProbeMap, UnsampledTexelsAreFilledNotBlack) {
  const MapLayout m{16, 8};
  ProbeMapState st;
  st.reset(m.texel_count());
  FrameSamples f;
  f.reset(m.texel_count());
  f.sum[0] = glm::vec3(4.0f);
  f.count[0] = 2.0f;  // one texel sampled, mean 2
  accumulate(st, f, {});
  const auto filled = filled_radiance(st, m, 2);
  for (std::size_t t = 0; t < filled.size(); ++t) EXPECT_EQ(filled[t], glm::vec3(2.0f)) << "texel " << t;
}

// The history is stored at half precision: one rounding of a value near 1
// (scale 1) is at most 2^-11.
constexpr float kHalfRounding = 0x1p-11f;

TEST(ProbeMap, HysteresisAdaptsOnlyToChangesBeyondTheNoise) {
  const MapLayout m{4, 2};
  ProbeMapState st;
  st.reset(m.texel_count());
  FrameSamples f;
  f.reset(m.texel_count());
  f.count[0] = 1;
  AccumulationSettings settings;
  settings.warmup_frames = 0;  // this test is about change detection, not the cold start
  // Steady light with +-10 % noise: slow blending throughout (h = 0.95).
  for (int i = 0; i < 40; ++i) {
    f.sum[0] = glm::vec3(i % 2 ? 1.1f : 0.9f);
    const float before = st.radiance_at(0).r;
    accumulate(st, f, settings);
    if (i > 0) {
      EXPECT_NEAR(st.radiance_at(0).r, 0.95f * before + 0.05f * f.sum[0].r, kHalfRounding) << "frame " << i;
    }
  }
  // The light goes off: far beyond the noise, so the fast blend (h = 0.5) applies.
  const float before = st.radiance_at(0).r;
  f.sum[0] = glm::vec3(0.0f);
  accumulate(st, f, settings);
  EXPECT_NEAR(st.radiance_at(0).r, 0.5f * before, kHalfRounding);
}

// A firefly (one texel catching a glint 1,000 times the map's light) is noise,
// not a change of light: it blends in at the slow weight and the texels it
// did not touch keep their history. A change over a quarter of the map (a
// lamp on one side) is still a change.
TEST(ProbeMap, AFireflyIsNotAChangeButALampOnOneSideIs) {
  const MapLayout m{16, 8};
  AccumulationSettings settings;
  settings.warmup_frames = 0;
  const auto steady = [&](ProbeMapState& st, FrameSamples& f) {
    st.reset(m.texel_count());
    f.reset(m.texel_count());
    engine::math::Pcg32 rng = engine::math::make_rng(7, 0, 0);
    for (int i = 0; i < 40; ++i) {  // independent +-10 % noise on every texel
      for (int t = 0; t < m.texel_count(); ++t) {
        f.sum[static_cast<std::size_t>(t)] = glm::vec3(0.9f + 0.2f * rng.next_float());
        f.count[static_cast<std::size_t>(t)] = 1;
      }
      accumulate(st, f, settings);
    }
  };
  ProbeMapState st;
  FrameSamples f;
  steady(st, f);
  const float firefly_before = st.radiance_at(37).r, other_before = st.radiance_at(5).r;
  f.sum[37] = glm::vec3(1000.0f);
  EXPECT_FALSE(accumulate(st, f, settings)) << "one texel 1,000x brighter was judged a change of light";
  EXPECT_NEAR(st.radiance_at(37).r, 0.95f * firefly_before + 0.05f * 1000.0f, 1e-3f * 50.0f)
      << "the firefly texel should blend in at the slow weight (h = 0.95)";
  EXPECT_NEAR(st.radiance_at(5).r, 0.95f * other_before + 0.05f * f.sum[5].r, kHalfRounding);

  steady(st, f);
  const float lit_before = st.radiance_at(3).r;
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width / 4; ++x) f.sum[static_cast<std::size_t>(y * m.width + x)] = glm::vec3(8.0f);
  EXPECT_TRUE(accumulate(st, f, settings)) << "a quarter of the map 8x brighter was not judged a change of light";
  EXPECT_NEAR(st.radiance_at(3).r, 0.5f * lit_before + 0.5f * 8.0f, 4 * kHalfRounding * 8.0f)
      << "a change of light should blend fast (h = 0.5)";
}

TEST(ProbeMap, ColdStartRampsTheHysteresisUp) {
  const MapLayout m{4, 2};
  ProbeMapState st;
  st.reset(m.texel_count());
  FrameSamples f;
  f.reset(m.texel_count());
  f.count[0] = 1;
  const AccumulationSettings s;  // ramp 0.5 -> 0.95 over 32 frames
  for (int frame = 0; frame < 40; ++frame) {
    f.sum[0] = glm::vec3(frame % 2 ? 1.05f : 0.95f);
    const float before = st.radiance_at(0).r;
    accumulate(st, f, s);
    if (frame == 0) continue;  // the first sample initialises the texel
    const float h = frame < 32 ? 0.5f + 0.45f * static_cast<float>(frame) / 32.0f : 0.95f;
    EXPECT_NEAR(st.radiance_at(0).r, h * before + (1 - h) * f.sum[0].r, kHalfRounding) << "frame " << frame;
  }
}

// The history is half precision in units of a power-of-two scale, so a steady
// light is held to one ulp (2^-10 relative at most) whether it is a millionth
// or a million times the level's, and the scale follows when the light
// changes by that much.
TEST(ProbeMap, HistoryHoldsASteadyLightToOneUlpAtAnyBrightness) {
  const MapLayout m{4, 2};
  for (float brightness : {1e-6f, 1.0f, 1e6f}) {
    ProbeMapState st;
    st.reset(m.texel_count());
    FrameSamples f;
    f.reset(m.texel_count());
    f.count[0] = 1;
    const glm::vec3 value = brightness * glm::vec3(1.0f, 0.37f, 0.011f);
    f.sum[0] = value;
    for (int i = 0; i < 50; ++i) accumulate(st, f, {});
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(st.radiance_at(0)[c], value[c], 0x1p-10f * value[c])
          << "brightness " << brightness << " channel " << c << ": expected " << value[c] << ", got " << st.radiance_at(0)[c];
    // The light jumps 1e6 times brighter: the scale follows, nothing saturates.
    f.sum[0] = value * 1e6f;
    for (int i = 0; i < 200; ++i) accumulate(st, f, {});
    EXPECT_NEAR(st.radiance_at(0).r, value.r * 1e6f, 1e-3f * value.r * 1e6f) << "brightness " << brightness << " x 1e6";
  }
}

// Depth is stored as half-precision mean and variance in units of the grid
// spacing: at 1 mm and at 10 km grids they follow the exponential moments of
// the distances (kept in double here) as closely as at 1 m.
TEST(DepthMap, MeanAndVarianceFollowTheMomentsAtAnyScale) {
  const MapLayout m{8, 4};
  const glm::vec3 dir(0, 1, 0);
  const AccumulationSettings settings;
  for (float unit : {1e-3f, 1.0f, 1e4f}) {
    ProbeMapState st;
    st.reset(m.texel_count(), unit);
    engine::math::Pcg32 rng(4, 4);
    double m1 = 0, m2 = 0;
    for (int frame = 0; frame < 300; ++frame) {
      const float d = unit * (3.0f + 0.4f * (rng.next_float() - 0.5f));
      update_own_depth(st, m, {{dir * d, glm::vec3(0.0f), dir, d, -dir}}, settings);
      const double ramp = std::min(1.0, frame / static_cast<double>(settings.warmup_frames));
      const double h = std::min<double>(settings.hysteresis, settings.fast_hysteresis + (settings.hysteresis - settings.fast_hysteresis) * ramp);
      m1 = frame == 0 ? d : h * m1 + (1 - h) * d;
      m2 = frame == 0 ? static_cast<double>(d) * d : h * m2 + (1 - h) * static_cast<double>(d) * d;
    }
    const auto t = static_cast<std::size_t>(m.texel_of(dir));
    const double variance = m2 - m1 * m1;
    EXPECT_NEAR(st.depth.mean(t), m1, 1e-3 * m1) << "unit " << unit;
    EXPECT_NEAR(st.depth.variance(t), variance, 0.02 * variance) << "unit " << unit << ": expected variance " << variance << ", got "
                                                                   << st.depth.variance(t);
  }
}

// ---- interpolation ---------------------------------------------------------------

#include "probes/interpolation.h"

namespace {
// Depth moments in 70 % of every probe's texels (hits 0.2 to 1.7 away), so
// the visibility test prunes some corners.
std::vector<ProbeMapState> random_depth_states(const ProbeGrid& g, const MapLayout& m, engine::math::Pcg32& rng) {
  std::vector<ProbeMapState> states(static_cast<std::size_t>(g.count()));
  for (auto& st : states) {
    st.reset(m.texel_count());
    for (int t = 0; t < m.texel_count(); ++t)
      if (rng.next_float() < 0.7f) st.depth.set(static_cast<std::size_t>(t), 0.2f + 1.5f * rng.next_float(), 0.05f * rng.next_float());
  }
  return states;
}

std::vector<ProbeMapState> open_space_states(const ProbeGrid& g, const MapLayout& m) {
  std::vector<ProbeMapState> s(static_cast<std::size_t>(g.count()));
  for (auto& st : s) st.reset(m.texel_count());  // no hits recorded: nothing occludes
  return s;
}
}  // namespace

// interpolate_probes computes the cage's geometry as 8-lane vectors; the
// reference one corner at a time. Same arithmetic, no contraction: the same
// bits, on relocated probes with depth that occludes some corners, at points
// on and off the probes.
TEST(Interpolation, VectorisedGeometryEqualsTheReferenceBitForBit) {
  ProbeGrid g{{-2, 0, -2}, {2, 3, 2}, {5, 4, 5}};
  g.offsets.resize(static_cast<std::size_t>(g.count()));
  engine::math::Pcg32 rng(12, 3);
  for (glm::vec3& o : g.offsets) o = 0.2f * glm::vec3(rng.next_float() - 0.5f, rng.next_float() - 0.5f, rng.next_float() - 0.5f);
  const MapLayout m{50, 25};
  const std::vector<ProbeMapState> states = random_depth_states(g, m, rng);
  const InterpolationSettings settings;
  int pruned = 0, compared = 0;
  for (int i = 0; i < 20000; ++i) {
    glm::vec3 p = g.min + (g.max - g.min) * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
    if (i % 100 == 0) p = g.position(i % g.count());  // exactly on a probe
    const glm::vec3 n = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
    const InterpolationResult fast = interpolate_probes(g, m, states, p, n, settings);
    const InterpolationResult ref = interpolate_probes_reference(g, m, states, p, n, settings);
    ASSERT_EQ(fast.probes, ref.probes) << "point " << i;
    ASSERT_EQ(fast.weights, ref.weights) << "point " << i;
    ASSERT_EQ(fast.pruned, ref.pruned) << "point " << i;
    ASSERT_EQ(fast.fallback, ref.fallback) << "point " << i;
    pruned += ref.pruned;
    ++compared;
  }
  EXPECT_GT(pruned, compared) << "the depth must prune some corners, or the visibility path went untested";
}

// interpolate_probes_many (batches of cages, their depth texels fetched
// together) gives each point what interpolate_probes gives it, bit for bit,
// over batches with ragged ends and some probes unusable.
TEST(Interpolation, ManyPointsAtOnceEqualOneAtATime) {
  ProbeGrid g{{-2, 0, -2}, {2, 3, 2}, {5, 4, 5}};
  engine::math::Pcg32 rng(31, 3);
  const MapLayout m{50, 25};
  const std::vector<ProbeMapState> states = random_depth_states(g, m, rng);
  std::vector<std::uint8_t> usable(static_cast<std::size_t>(g.count()), 1);
  for (std::size_t q = 0; q < usable.size(); q += 7) usable[q] = 0;
  const InterpolationSettings settings;
  for (const std::size_t n : {std::size_t{1}, std::size_t{16}, std::size_t{37}, std::size_t{200}}) {
    std::vector<glm::vec3> p(n), nrm(n);
    for (std::size_t i = 0; i < n; ++i) {
      p[i] = g.min + (g.max - g.min) * glm::vec3(rng.next_float(), rng.next_float(), rng.next_float());
      nrm[i] = engine::math::sample_uniform_sphere({rng.next_float(), rng.next_float()});
    }
    std::vector<InterpolationResult> many(n);
    interpolate_probes_many(g, m, states, p, nrm, settings, usable, many);
    int pruned = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const InterpolationResult one = interpolate_probes(g, m, states, p[i], nrm[i], settings, usable);
      ASSERT_EQ(many[i].probes, one.probes) << n << " points, point " << i;
      ASSERT_EQ(many[i].weights, one.weights) << n << " points, point " << i;
      ASSERT_EQ(many[i].pruned, one.pruned) << n << " points, point " << i;
      ASSERT_EQ(many[i].fallback, one.fallback) << n << " points, point " << i;
      pruned += one.pruned;
    }
    if (n >= 37) {
      EXPECT_GT(pruned, 0) << "the depth must prune some corners";
    }
  }
}

TEST(Interpolation, UnprunedWeightsAreTrilinear) {
  const ProbeGrid g{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  const MapLayout m{32, 16};
  const auto states = open_space_states(g, m);
  const glm::vec3 p(0.3f, 0.6f, 0.2f);
  const auto r = interpolate_probes(g, m, states, p, glm::normalize(glm::vec3(1, 1, 1)), {.prune_back_facing = false});
  const auto c = g.cage(p);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(r.weights[i], c.weights[i], 1e-6f);
  EXPECT_EQ(r.pruned, 0);
}

TEST(Interpolation, BackFacingProbesArePruned) {
  const ProbeGrid g{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  const MapLayout m{32, 16};
  const auto states = open_space_states(g, m);
  // A floor at y = 0.5 facing up: the four probes at y = 0 are below it.
  const auto r = interpolate_probes(g, m, states, {0.5f, 0.5f, 0.5f}, {0, 1, 0}, {});
  EXPECT_EQ(r.pruned, 4);
  for (std::size_t i = 0; i < 8; ++i) {
    const bool below = g.position(r.probes[i]).y < 0.5f;
    EXPECT_NEAR(r.weights[i], below ? 0.0f : 0.25f, 1e-6f) << "probe " << r.probes[i];
  }
}

namespace {
// Probe 1 (at x = 1 in a row of two) records one own hit a texel, at the
// distance `hit_at(direction)` gives (none where it gives 0).
template <class HitAt>
void record_probe1_hits(std::vector<ProbeMapState>& states, const MapLayout& m, HitAt hit_at) {
  std::vector<ShadedPoint> hits;
  for (int t = 0; t < m.texel_count(); ++t) {
    const glm::vec3 d = m.direction_of(t);
    const float along = hit_at(d);
    if (along > 0) hits.push_back({glm::vec3(1, 0, 0) + d * along, glm::vec3(0), d, along});
  }
  update_own_depth(states[1], m, hits, {});
}
}  // namespace

TEST(Interpolation, OccludedProbeIsPrunedByChebyshev) {
  const ProbeGrid g{{0, 0, 0}, {1, 0, 0}, {2, 1, 1}};
  const MapLayout m{32, 16};
  auto states = open_space_states(g, m);
  // Probe 1 at x = 1 has a wall at x = 0.8: its own rays towards -x hit it.
  record_probe1_hits(states, m, [](const glm::vec3& d) { return d.x < -0.1f ? 0.2f / -d.x : 0.0f; });
  // A point at x = 0.4 facing +y (so neither probe is behind it): probe 1
  // must not see it through the wall, probe 0 takes all the weight.
  const auto r = interpolate_probes(g, m, states, {0.4f, 0, 0}, {0, 1, 0}, {});
  EXPECT_FALSE(r.fallback);
  float w0 = 0, w1 = 0;
  for (std::size_t i = 0; i < 8; ++i) (r.probes[i] == 0 ? w0 : w1) += r.weights[i];
  EXPECT_EQ(w1, 0.0f) << "probe 1 is occluded";
  EXPECT_NEAR(w0, 1.0f, 1e-6f);
  EXPECT_NEAR(chebyshev_visibility(0.2f, 0.0f, 0.6f), 0.0f, 1e-3f);
  EXPECT_EQ(chebyshev_visibility(0.2f, 0.0f, 0.1f), 1.0f) << "closer than the wall: visible";
}

// Known answers: at a texel's centre its own moments; half-way between two
// texels at depths 1 and 2 the mean 1.5 and the variance 0.25 (so a point
// at 2 is seen with bound 0.5), also across the map's u seam; texels no ray
// hit are left out, and a footprint of them alone sees everything.
TEST(Interpolation, FilteredVisibilityReadsTheBilinearMomentsOfTheFourNearestTexels) {
  const MapLayout m{8, 4};
  DepthMap depth;
  depth.reset(m.texel_count(), 0.5f);
  const auto at = [&](int x, int y) { return static_cast<std::size_t>(y * m.width + x); };
  depth.set(at(2, 1), 1.0f, 0.01f);
  const float seen = filtered_visibility(depth, m, {2.5f, 1.5f}, 1.5f);
  EXPECT_NEAR(seen, chebyshev_visibility(depth.mean(at(2, 1)), depth.variance(at(2, 1)), 1.5f), 1e-6f);
  EXPECT_LT(seen, 0.1f);

  depth.set(at(3, 2), 1.0f, 0.0f);
  depth.set(at(4, 2), 2.0f, 0.0f);
  EXPECT_NEAR(filtered_visibility(depth, m, {4.0f, 2.5f}, 2.0f), 0.5f, 1e-5f);
  depth.set(at(7, 3), 1.0f, 0.0f);
  depth.set(at(0, 3), 2.0f, 0.0f);
  EXPECT_NEAR(filtered_visibility(depth, m, {0.0f, 3.5f}, 2.0f), 0.5f, 1e-5f) << "across the u seam";
  EXPECT_NEAR(filtered_visibility(depth, m, {8.0f, 3.5f}, 2.0f), 0.5f, 1e-5f) << "across the u seam, from the right";

  // Row 0: texel 5 hit at 1, texel 4 never hit.
  depth.set(at(5, 0), 1.0f, 0.0f);
  EXPECT_EQ(filtered_visibility(depth, m, {4.5f, 0.5f}, 2.5f), 1.0f) << "no hit: nothing hides the point";
  for (const float x : {4.6f, 5.0f, 5.5f})
    EXPECT_NEAR(filtered_visibility(depth, m, {x, 0.5f}, 2.5f), chebyshev_visibility(1.0f, 0.0f, 2.5f), 1e-6f)
        << "the hit decides wherever it weighs";
}

// A probe beyond a wall's edge: points sliding past the edge see it fade in
// with the ramp; the paper's cut (softness 0) flips it from nothing to its
// whole trilinear weight between two points a tenth of a millimetre apart.
TEST(Interpolation, AProbeBeyondAWallsEdgeFadesInInsteadOfFlipping) {
  const ProbeGrid g{{0, 0, 0}, {1, 0, 0}, {2, 1, 1}};
  const MapLayout m{32, 16};
  auto states = open_space_states(g, m);
  // Probe 1 at x = 1: a wall at x = 0.8 below y = 0; above it, the room's
  // far wall at x = -1.
  record_probe1_hits(states, m, [](const glm::vec3& d) { return d.x > -0.1f ? 0.0f : (d.y < 0 ? 0.2f : 2.0f) / -d.x; });
  const auto probe1_weight = [&](float y, const InterpolationSettings& s) {
    const InterpolationResult r = interpolate_probes(g, m, states, {0.4f, y, 0.0f}, {0, 0, 1}, s);
    float w = 0;
    for (std::size_t i = 0; i < 8; ++i) w += r.probes[i] == 1 ? r.weights[i] : 0.0f;
    return w;
  };
  const InterpolationSettings ramp, cut{.visibility_ramp = 0.0f};
  EXPECT_EQ(probe1_weight(-0.1f, ramp), 0.0f) << "behind the wall";
  EXPECT_NEAR(probe1_weight(0.1f, ramp), 0.4f, 1e-5f) << "in the open: its trilinear weight";
  float ramp_step = 0, cut_step = 0;
  for (int i = 1; i <= 2000; ++i) {
    const float y0 = -0.1f + 1e-4f * static_cast<float>(i - 1), y1 = y0 + 1e-4f;
    ramp_step = std::max(ramp_step, std::abs(probe1_weight(y1, ramp) - probe1_weight(y0, ramp)));
    cut_step = std::max(cut_step, std::abs(probe1_weight(y1, cut) - probe1_weight(y0, cut)));
  }
  EXPECT_LT(ramp_step, 0.05f);
  EXPECT_GT(cut_step, 0.2f) << "the cut flips (what the ramp is for)";
}

// A cornice facet facing down, 5 mm inside a single-sheet wall (z = 0):
// the probes beyond the wall see the wall a centimetre before the point, well
// inside their texels' spread of distances (a grazing texel's), so the
// Chebyshev test keeps them. Moved towards the viewer in the room, the test
// point lies a tenth of a cell off the wall and they are pruned; without a
// viewer they are not (the leak the view bias is for).
TEST(Interpolation, TheViewBiasKeepsProbesBeyondAThinWallFromAPointBesideIt) {
  const ProbeGrid g{{-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}, {2, 2, 2}};
  const MapLayout m{50, 25};  // the real-time preset's maps
  auto states = open_space_states(g, m);
  for (int q = 0; q < g.count(); ++q) {
    const glm::vec3 probe = g.position(q);
    if (probe.z < 0) continue;  // inside the room: nothing in the way
    for (int t = 0; t < m.texel_count(); ++t) {
      const glm::vec3 d = m.direction_of(t);
      if (d.z >= -0.05f) continue;
      const float to_wall = probe.z / -d.z;
      states[static_cast<std::size_t>(q)].depth.set(static_cast<std::size_t>(t), to_wall, 0.0025f * to_wall * to_wall);
    }
  }
  const glm::vec3 p(0.1f, 0.1f, -0.005f), n(0.0f, -1.0f, 0.0f), camera(0.1f, -0.3f, -2.0f);
  const auto beyond_the_wall = [&](const glm::vec3* viewer) {
    const InterpolationResult r = interpolate_probes(g, m, states, p, n, {}, {}, viewer);
    float w = 0;
    for (std::size_t i = 0; i < 8; ++i) w += g.position(r.probes[i]).z > 0 ? r.weights[i] : 0.0f;
    EXPECT_FALSE(r.fallback);
    return w;
  };
  EXPECT_GT(beyond_the_wall(nullptr), 0.3f) << "without a viewer the outside probes leak in";
  EXPECT_EQ(beyond_the_wall(&camera), 0.0f);
  EXPECT_EQ(visibility_test_point(g, p, n, InterpolationSettings{}, nullptr), p + n * 0.1f);
  EXPECT_NEAR(glm::length(visibility_test_point(g, p, n, InterpolationSettings{}, &camera) - (p + n * 0.1f)), 0.1f, 1e-6f);
}

TEST(Interpolation, AllPrunedFallsBackToDistanceAndCosineWeights) {
  const ProbeGrid g{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  const MapLayout m{32, 16};
  const auto states = open_space_states(g, m);
  // A point above the whole grid facing up: every probe is behind it.
  const auto r = interpolate_probes(g, m, states, {0.5f, 1.5f, 0.5f}, {0, 1, 0}, {});
  EXPECT_TRUE(r.fallback);
  float sum = 0;
  for (float w : r.weights) {
    EXPECT_GT(w, 0.0f);
    sum += w;
  }
  EXPECT_NEAR(sum, 1.0f, 1e-5f);
}
