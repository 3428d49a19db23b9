#include "bake/dataset.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "engine/jobs/parallel_for.h"
#include "model/transfer_model.h"

namespace transgi::bake {

std::vector<int> points_per_mesh(const std::vector<double>& area, const std::vector<std::size_t>& vertices,
                                 const DatasetSettings& s) {
  const std::size_t n = area.size();
  std::vector<int> points(n, 0);
  std::vector<double> cap(n, std::numeric_limits<double>::infinity());
  if (s.max_points_per_vertex > 0)
    for (std::size_t m = 0; m < n; ++m)
      cap[m] = std::max<double>(s.min_points_per_mesh, static_cast<double>(s.max_points_per_vertex) * static_cast<double>(vertices[m]));
  // Water-filling: meshes whose share by area exceeds their cap take the cap;
  // the rest share what is left by area. Each round caps at least one more
  // mesh or ends, so at most n rounds.
  std::vector<char> capped(n, 0);
  for (std::size_t round = 0; round <= n; ++round) {
    double left = s.points, free_area = 0;
    for (std::size_t m = 0; m < n; ++m) {
      if (capped[m]) left -= cap[m];
      else if (area[m] > 0) free_area += area[m];
    }
    bool more = false;
    for (std::size_t m = 0; m < n; ++m)
      if (!capped[m] && area[m] > 0 && left * area[m] / free_area > cap[m]) capped[m] = 1, more = true;
    if (more) continue;
    for (std::size_t m = 0; m < n; ++m) {
      if (area[m] <= 0) continue;
      const double share = capped[m] ? cap[m] : std::max(0.0, left) * area[m] / free_area;
      points[m] = std::max(s.min_points_per_mesh, static_cast<int>(std::lround(share)));
    }
    break;
  }
  return points;
}

TransferDataset generate_dataset(const engine::scene::SceneAssets& assets, const DatasetSettings& s,
                                 const std::function<void(std::size_t, std::size_t)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t mesh_count = assets.meshes.size();
  // Points per mesh: by area, with a floor.
  std::vector<double> area(mesh_count, 0.0);
  for (std::size_t m = 0; m < mesh_count; ++m) {
    const auto& mesh = *assets.meshes[m];
    for (const glm::uvec3& t : mesh.triangles)
      area[m] += 0.5 * glm::length(glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]));
  }
  std::vector<std::size_t> vertices(mesh_count);
  for (std::size_t m = 0; m < mesh_count; ++m) vertices[m] = assets.meshes[m]->positions.size();
  const std::vector<int> points = points_per_mesh(area, vertices, s);
  std::size_t total_points = 0;
  for (int p : points) total_points += static_cast<std::size_t>(p);

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
        if (s.demodulate) {
          const glm::vec3 d = model::demodulation(sp.brdf.base_color);
          for (std::size_t j = 0; j < wo.size(); ++j)
            for (int c = 0; c < 3; ++c)
              for (int k = 0; k < engine::math::kShCount; ++k) r.targets[j * kTransferValues + static_cast<std::size_t>(c * engine::math::kShCount + k)] /= d[c];
        }
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
  d.demodulated = s.demodulate;
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
