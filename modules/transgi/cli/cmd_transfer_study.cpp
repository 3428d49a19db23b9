// Error of the transfer estimator against ray count: at random surface
// points of every mesh, estimate t with N rays and compare with a 16k-ray
// reference; prints relative RMSE for the pooled BRDF mixture (the bake's
// estimator) and for cosine-only sampling.
#include <cmath>
#include <chrono>
#include <cstdio>
#include <mutex>

#include "bake/transfer.h"
#include "cli/args.h"
#include "cli/commands.h"
#include "engine/jobs/job_system.h"
#include "engine/jobs/parallel_for.h"
#include "engine/scene/gltf_loader.h"

namespace transgi::cli {

int run_transfer_study(const std::vector<std::string>& argv) {
  const Args args("transfer-study", argv, {"scene", "points", "outgoing", "reference-rays", "threads", "seed"});
  const int points = static_cast<int>(args.integer("points", 1, 100000, 48));
  const int K = static_cast<int>(args.integer("outgoing", 1, 64, 8));
  const int ref_rays = static_cast<int>(args.integer("reference-rays", 1024, 10'000'000, 16384));
  const auto seed = static_cast<std::uint64_t>(args.integer("seed", 0, INT64_MAX, 3));
  engine::jobs::JobSystem jobs({.threads = static_cast<int>(args.integer("threads", 0, 1024, 0))});
  engine::ecs::World world;
  engine::scene::load_gltf(world, args.str("scene"));  // checked as every command checks a scene
  const auto& assets = world.resource<engine::scene::SceneAssets>();
  const std::vector<int> counts = {256, 512, 1000, 2000};
  struct Acc {
    double err2 = 0, ref2 = 0;
  };
  std::vector<Acc> mix(counts.size()), cosine(counts.size());
  // Points spread evenly over meshes (largest first is not needed: every mesh counts).
  std::vector<std::pair<std::uint32_t, int>> jobs_list;
  for (std::uint32_t m = 0; m < assets.meshes.size(); ++m)
    if (!assets.meshes[m]->triangles.empty()) jobs_list.emplace_back(m, 0);
  const int per_mesh = std::max(1, points / static_cast<int>(jobs_list.size()));
  double seconds_mix[4] = {}, seconds_cos[4] = {};
  jobs.run([&] {
    for (const auto& job : jobs_list) {
      const auto m = job.first;  // a plain variable: clang 14 cannot capture a structured binding
      const auto tracer = bake::make_object_tracer(assets, m);
      const bake::MeshTransfer mt(*tracer, *assets.meshes[m], assets, bake::default_visibility_distance(*assets.meshes[m]));
      std::vector<std::vector<double>> local(counts.size() * 2, std::vector<double>(2, 0.0));
      std::mutex lock;
      engine::jobs::parallel_for(0, per_mesh, 1, [&](int b, int e) {
        for (int p = b; p < e; ++p) {
          engine::math::Pcg32 rng = engine::math::make_rng(seed, (std::uint64_t{m} << 20) | static_cast<std::uint64_t>(p), 0);
          const bake::SurfacePoint sp = mt.sample_point(rng);
          std::vector<glm::vec3> wo(static_cast<std::size_t>(K));
          for (auto& w : wo) w = bake::MeshTransfer::sample_outgoing(sp, rng);
          std::vector<float> ref(static_cast<std::size_t>(K) * bake::kTransferValues), est(ref.size());
          mt.estimate(sp, wo, ref_rays, rng, ref);
          for (std::size_t c = 0; c < counts.size(); ++c)
            for (int which = 0; which < 2; ++which) {
              const auto t0 = std::chrono::steady_clock::now();
              mt.estimate(sp, wo, counts[c], rng, est, which == 0 ? bake::Proposal::BrdfMixture : bake::Proposal::CosineOnly);
              const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
              double e2 = 0, r2 = 0;
              for (std::size_t i = 0; i < ref.size(); ++i) {
                e2 += (est[i] - ref[i]) * (est[i] - ref[i]);
                r2 += ref[i] * ref[i];
              }
              std::scoped_lock g(lock);
              (which == 0 ? mix : cosine)[c].err2 += e2;
              (which == 0 ? mix : cosine)[c].ref2 += r2;
              (which == 0 ? seconds_mix : seconds_cos)[c] += secs;
            }
        }
      });
    }
  });
  std::printf("transfer estimator error vs %d-ray reference, %d points x %d outgoing directions over %zu meshes\n", ref_rays,
              per_mesh * static_cast<int>(jobs_list.size()), K, jobs_list.size());
  std::printf("%8s %22s %22s %14s %14s\n", "rays", "rel. RMSE BRDF mixture", "rel. RMSE cosine only", "ms/pt mixture", "ms/pt cosine");
  const double npts = per_mesh * static_cast<double>(jobs_list.size());
  for (std::size_t c = 0; c < counts.size(); ++c)
    std::printf("%8d %22.4f %22.4f %14.3f %14.3f\n", counts[c], std::sqrt(mix[c].err2 / mix[c].ref2),
                std::sqrt(cosine[c].err2 / cosine[c].ref2), 1e3 * seconds_mix[c] / npts, 1e3 * seconds_cos[c] / npts);
  return 0;
}

}  // namespace transgi::cli
