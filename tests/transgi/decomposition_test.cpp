// eval --decompose replaces one part of TransGI at a time by its oracle. The
// probe oracle must reach every field that shading reads, whatever the
// placement: with the cascades (the default since issue 16) it once reached
// none, and its row came out bit-identical to the base row.
#include <gtest/gtest.h>

#include <cmath>

#include "eval/decomposition.h"
#include "eval/method_runs.h"
#include "model/transfer_model.h"

using namespace transgi;

namespace {

const std::string kScene = std::string(TRANSGI_CONTENT_DIR) + "/test_scenes/cornell_box/scene.gltf";

// The largest absolute difference between two images of one size.
float max_difference(const engine::image::ImageRGB& a, const engine::image::ImageRGB& b) {
  float d = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const glm::vec3 e = glm::abs(a.at(x, y) - b.at(x, y));
      d = std::max(d, std::max(e.r, std::max(e.g, e.b)));
    }
  return d;
}

}  // namespace

TEST(Decomposition, OracleProbesReplaceTheProbesOfEveryPlacement) {
  constexpr int kW = 32, kH = 18;
  for (const auto mode : {runtime::ProbeVolumeMode::Scene, runtime::ProbeVolumeMode::Cascades}) {
    eval::TransgiRunOptions t;
    t.frames = 8;
    t.progress = false;
    t.settings.direct_spp = 0;
    t.settings.probes.map = probes::MapLayout{16, 8};
    t.placement.mode = mode;
    t.placement.scene_dims = glm::ivec3(4);
    t.placement.cascades.dims = glm::ivec3(4);
    eval::LoadedScene scene = eval::load_scene(kScene, "", 2);
    const eval::MethodRun run = eval::run_transgi(scene, std::make_shared<const model::TransferModel>(), kW, kH, t);
    eval::DecompositionOptions o;
    o.oracle_rays_per_texel = 2;
    o.ground_truth_rays = 8;
    o.gbuffer_spp = 2;
    const auto rows = eval::decompose_transgi(scene, run.gi, kW, kH, o);
    const eval::DecompositionRow* base = nullptr;
    const eval::DecompositionRow* oracle = nullptr;
    for (const auto& r : rows) {
      if (r.slug == "base") base = &r;
      if (r.slug == "oracle_probes") oracle = &r;
    }
    ASSERT_TRUE(base && oracle);
    const float diff = max_difference(base->gi, oracle->gi);
    EXPECT_GT(diff, 1e-4f) << runtime::name_of(mode) << ": the oracle-probe row should differ from the base row (probes "
                           << "path-traced instead of accumulated), got a largest pixel difference of " << diff;
    std::printf("%s: largest pixel difference, oracle probes against the run's %.4f\n", std::string(runtime::name_of(mode)).c_str(), diff);
  }
}
