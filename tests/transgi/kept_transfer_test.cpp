// Kept transfer (gi_history.h, RealtimeGiSettings::transfer_max_age): cells
// keep the network's decoded transfer across frames and only take each
// frame's light. The reference is the same frame with every cell decoded
// (reuse off): the two differ only in the order of the light's dot product
// where the kept transfer is the one decoding gives (a still view).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "edge_scene.h"
#include "engine/render/light_set.h"
#include "probes/probe_field.h"
#include "shading/fused_decoder.h"
#include "shading/realtime_gi.h"
#include "transfer_fixtures.h"

using namespace transgi;
using namespace engine;
using transgi_test::camera_at;
using transgi_test::EdgeScene;

namespace {

constexpr int kW = 96, kH = 64;

// The edge scene with a random network on every mesh, and two probe fields
// that light it differently (a coarse and a fine grid under the same sky).
struct Net {
  EdgeScene s;
  const rt::RtScene& rt;
  const scene::SceneAssets& assets;
  probes::ProbeField coarse, fine;
  model::TransferModel model;
  shading::FusedDecoder decoder;

  static probes::ProbeFieldSettings grid(glm::ivec3 counts) {
    probes::ProbeFieldSettings ps;
    ps.grid = probes::ProbeGrid::centred_in({-4, 0, -2}, {4, 3, 4}, counts);
    return ps;
  }
  static model::TransferModel make_model(const scene::SceneAssets& assets) {
    math::Pcg32 rng(21, 4);
    return random_model(assets, 32, rng);
  }
  Net()
      : rt(s.app.world().resource<rt::RtScene>()), assets(s.app.world().resource<scene::SceneAssets>()), coarse(grid({3, 2, 3})),
        fine(grid({6, 3, 6})), model(make_model(assets)), decoder(model.decoder) {
    const render::LightSet lights(rt, {}, &*assets.environment);
    s.app.jobs().run([&] {
      for (int f = 0; f < 30; ++f) {
        coarse.update(rt, lights);
        fine.update(rt, lights);
      }
    });
  }

  struct Frame {
    image::ImageRGB kept, decoded;
    shading::RealtimeGiStats stats;
  };
  // One frame from `camera` lit by `field`: through `scratch` with the
  // transfer kept, and with every cell decoded.
  Frame frame(const transform::Similarity& camera, const probes::ProbeField& field, shading::RealtimeGiScratch& scratch,
              int max_age = 64, float view_degrees = 2.0f) {
    Frame f;
    const render::CameraRays rays(scene::Camera{}, camera, kW, kH);
    const probes::ProbeField* fields[] = {&field};
    s.app.jobs().run([&] {
      const shading::GBuffer g = shading::trace_gbuffer(rt, assets, rays, kW, kH);
      shading::RealtimeGiRequest request{.gbuffer = g, .scene = rt, .assets = assets, .fields = fields, .model = &model, .decoder = &decoder};
      f.decoded = shading::shade_gi_realtime(request);
      request.settings.reuse_history = true;
      request.settings.transfer_max_age = max_age;
      request.settings.transfer_view_degrees = view_degrees;
      f.kept = shading::shade_gi_realtime(request, {.stats = &f.stats, .scratch = &scratch});
    });
    return f;
  }
};

// Largest |kept - decoded| over the image, and the decoded image's largest value.
std::pair<double, double> max_difference(const Net::Frame& f) {
  double diff = 0, peak = 0;
  for (std::size_t p = 0; p < f.decoded.pixels.size(); ++p) {
    const glm::vec3 d = glm::abs(f.kept.pixels[p] - f.decoded.pixels[p]);
    diff = std::max(diff, static_cast<double>(std::max({d.r, d.g, d.b})));
    peak = std::max(peak, static_cast<double>(std::max({f.decoded.pixels[p].r, f.decoded.pixels[p].g, f.decoded.pixels[p].b})));
  }
  return {diff, peak};
}

// The network samples on grid cells this frame (the rest are edge pixels, always decoded).
std::size_t grid_network_samples(const shading::RealtimeGiStats& st) { return st.inferred + st.kept_transfers - st.edge_samples; }

}  // namespace

// A still view: after the first two frames (one per checkerboard colour)
// nearly every lit cell takes its kept transfer, and the image is the
// decoded one up to the dot product's rounding.
TEST(KeptTransfer, AStillViewLitWithKeptTransferIsTheDecodedImage) {
  Net net;
  shading::RealtimeGiScratch scratch;
  const transform::Similarity cam = camera_at({0.3f, 1.2f, 3.5f});
  net.frame(cam, net.fine, scratch);
  net.frame(cam, net.fine, scratch);
  for (int f = 0; f < 3; ++f) {
    const Net::Frame next = net.frame(cam, net.fine, scratch);
    const auto [diff, peak] = max_difference(next);
    std::printf("frame %d: %zu of %zu network cells lit with a kept transfer; max |kept - decoded| %.3g (peak %.3g)\n", f + 3,
                next.stats.kept_transfers, grid_network_samples(next.stats), diff, peak);
    ASSERT_GT(peak, 0.01) << "the scene must have GI";
    EXPECT_GE(next.stats.kept_transfers, grid_network_samples(next.stats) * 95 / 100);
    EXPECT_LE(diff, 1e-5 * peak);
  }
}

// The light changes (another probe field): no cell decodes for it, and two
// frames later (both colours lit) the image is the decoded one under the
// new light.
TEST(KeptTransfer, ANewLightIsTakenWithoutDecoding) {
  Net net;
  shading::RealtimeGiScratch scratch;
  const transform::Similarity cam = camera_at({0.3f, 1.2f, 3.5f});
  for (int f = 0; f < 3; ++f) net.frame(cam, net.coarse, scratch);
  const Net::Frame first = net.frame(cam, net.fine, scratch), second = net.frame(cam, net.fine, scratch);
  for (const Net::Frame* f : {&first, &second})
    EXPECT_GE(f->stats.kept_transfers, grid_network_samples(f->stats) * 95 / 100) << "a light change must not decode";
  const auto [diff, peak] = max_difference(second);
  const double change = max_difference(Net::Frame{first.decoded, net.frame(cam, net.coarse, scratch).decoded, {}}).first;
  std::printf("the new light changed pixels by up to %.3g; two frames later max |kept - decoded| %.3g (peak %.3g)\n", change, diff, peak);
  ASSERT_GT(change, 0.05 * peak) << "the two fields must light the scene differently";
  EXPECT_LE(diff, 1e-5 * peak);
}

// The camera steps sideways: every point is seen from a few degrees off.
// With the 2-degree threshold the view-dependent transfer is decoded again;
// with 30 degrees it is kept.
TEST(KeptTransfer, AViewTurnedPastTheThresholdDecodesAgain) {
  for (const float degrees : {2.0f, 30.0f}) {
    Net net;
    shading::RealtimeGiScratch scratch;
    net.frame(camera_at({0.3f, 1.2f, 3.5f}), net.fine, scratch, 64, degrees);
    net.frame(camera_at({0.3f, 1.2f, 3.5f}), net.fine, scratch, 64, degrees);
    const Net::Frame step = net.frame(camera_at({0.65f, 1.2f, 3.5f}), net.fine, scratch, 64, degrees);
    const std::size_t cells = grid_network_samples(step.stats);
    std::printf("a 35 cm step, threshold %.0f degrees: %zu of %zu network cells kept their transfer\n", degrees, step.stats.kept_transfers, cells);
    if (degrees < 10)
      EXPECT_LT(step.stats.kept_transfers, cells / 10);
    else
      EXPECT_GT(step.stats.kept_transfers, cells * 6 / 10);
  }
}

// Transfer expires within max_age frames, spread over frames: a still view
// keeps decoding a share of its cells every frame, never all at once.
TEST(KeptTransfer, TransferIsRefreshedWithinItsLifetimeSpreadOverFrames) {
  Net net;
  shading::RealtimeGiScratch scratch;
  const transform::Similarity cam = camera_at({0.3f, 1.2f, 3.5f});
  constexpr int kMaxAge = 8;
  double least = 1, most = 0, sum = 0;
  int frames = 0;
  for (int f = 0; f < 30; ++f) {
    const Net::Frame next = net.frame(cam, net.fine, scratch, kMaxAge);
    if (f < 3 * kMaxAge / 2) continue;  // past the first lifetimes
    const std::size_t cells = grid_network_samples(next.stats);
    const double decoded = 1.0 - static_cast<double>(next.stats.kept_transfers) / static_cast<double>(cells);
    least = std::min(least, decoded);
    most = std::max(most, decoded);
    sum += decoded;
    ++frames;
  }
  std::printf("max age %d: each frame decoded %.3f to %.3f of its network cells, mean %.3f\n", kMaxAge, least, most, sum / frames);
  // Lifetimes of 4 to 8 frames, a cell looked at every other frame: each
  // transfer lives 2 to 4 of its looks, about a third of the cells a frame.
  EXPECT_GT(least, 0.1) << "every frame must refresh some cells";
  EXPECT_LT(most, 0.6) << "the refreshes must not come at once";
  EXPECT_NEAR(sum / frames, 1.0 / 3.0, 0.1);
}

// A material edited in place (the editor bumps SceneAssets::edit_version):
// the network reads each point's base colour, so nothing kept before the
// edit is taken after it; once each colour has decoded again (two frames),
// the cells keep again.
TEST(KeptTransfer, AnEditedMaterialIsDecodedAgain) {
  Net net;
  shading::RealtimeGiScratch scratch;
  const transform::Similarity cam = camera_at({0.3f, 1.2f, 3.5f});
  for (int f = 0; f < 3; ++f) net.frame(cam, net.fine, scratch);
  auto& assets = net.s.app.world().resource<scene::SceneAssets>();
  assets.materials[0].base_color_factor = glm::vec4(0.2f, 0.5f, 0.3f, 1.0f);
  ++assets.edit_version;
  const Net::Frame edited = net.frame(cam, net.fine, scratch);
  net.frame(cam, net.fine, scratch);
  const Net::Frame after = net.frame(cam, net.fine, scratch);
  std::printf("after the edit: %zu kept; two frames later: %zu of %zu\n", edited.stats.kept_transfers, after.stats.kept_transfers,
              grid_network_samples(after.stats));
  EXPECT_EQ(edited.stats.kept_transfers, 0u) << "a transfer decoded with the old colour was taken";
  EXPECT_GE(after.stats.kept_transfers, grid_network_samples(after.stats) * 95 / 100) << "the cells must keep again";
}
