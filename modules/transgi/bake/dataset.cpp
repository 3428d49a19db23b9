#include "bake/dataset.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>

#include "engine/jobs/parallel_for.h"

namespace transgi::bake {

TransferDataset generate_dataset(const engine::scene::SceneAssets& assets, const DatasetSettings& s,
                                 const std::function<void(std::size_t, std::size_t)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t mesh_count = assets.meshes.size();
  // Points per mesh: by area, with a floor.
  std::vector<double> area(mesh_count, 0.0);
  double total_area = 0;
  for (std::size_t m = 0; m < mesh_count; ++m) {
    const auto& mesh = *assets.meshes[m];
    for (const glm::uvec3& t : mesh.triangles)
      area[m] += 0.5 * glm::length(glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]));
    total_area += area[m];
  }
  std::vector<int> points(mesh_count, 0);
  std::size_t total_points = 0;
  for (std::size_t m = 0; m < mesh_count; ++m) {
    if (area[m] <= 0) continue;
    points[m] = std::max(s.min_points_per_mesh, static_cast<int>(std::lround(s.points * area[m] / total_area)));
    total_points += static_cast<std::size_t>(points[m]);
  }

  const int K = s.outgoing_per_point;
  struct PointResult {
    std::vector<TransferSample> samples;
    std::vector<float> targets;
  };
  std::vector<PointResult> results(total_points);
  std::atomic<std::size_t> done{0};
  std::size_t first = 0;
  for (std::size_t m = 0; m < mesh_count; ++m) {
    if (points[m] == 0) continue;
    const auto tracer = make_object_tracer(assets, static_cast<std::uint32_t>(m));
    const MeshTransfer transfer(*tracer, *assets.meshes[m], assets,
                                s.visibility_fraction * glm::length(assets.meshes[m]->bounds_max - assets.meshes[m]->bounds_min));
    engine::jobs::parallel_for(0, points[m], 4, [&](int b, int e) {
      for (int p = b; p < e; ++p) {
        const std::size_t global = first + static_cast<std::size_t>(p);
        engine::math::Pcg32 rng = engine::math::make_rng(s.seed, global, 0);
        const SurfacePoint sp = transfer.sample_point(rng);
        std::vector<glm::vec3> wo(static_cast<std::size_t>(K));
        for (auto& w : wo) w = MeshTransfer::sample_outgoing(sp, rng);
        PointResult& r = results[global];
        r.targets.resize(static_cast<std::size_t>(K) * kTransferValues);
        transfer.estimate(sp, wo, s.rays, rng, r.targets);
        for (const glm::vec3& w : wo)
          r.samples.push_back({static_cast<std::uint32_t>(m), sp.triangle, sp.barycentric, sp.shading_normal, w, sp.brdf.base_color});
        const std::size_t n = done.fetch_add(1) + 1;
        if (progress && n % 64 == 0) progress(n, total_points);
      }
    });
    first += static_cast<std::size_t>(points[m]);
  }
  if (progress) progress(total_points, total_points);

  // Split by point: every (1 / fraction)-th point, deterministic, goes to validation.
  TransferDataset d;
  std::vector<std::size_t> train, valid;
  const std::size_t stride = s.validation_fraction > 0 ? std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(1.0 / s.validation_fraction))) : 0;
  for (std::size_t p = 0; p < total_points; ++p) (stride && p % stride == stride - 1 ? valid : train).push_back(p);
  for (const auto* set : {&train, &valid})
    for (std::size_t p : *set) {
      d.samples.insert(d.samples.end(), results[p].samples.begin(), results[p].samples.end());
      d.targets.insert(d.targets.end(), results[p].targets.begin(), results[p].targets.end());
    }
  d.training_count = train.size() * static_cast<std::size_t>(K);
  d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

}  // namespace transgi::bake
