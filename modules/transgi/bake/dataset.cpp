#include "bake/dataset.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>

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

std::uint32_t point_hash(std::uint64_t seed, std::size_t point) {
  return engine::math::hash32(engine::math::hash_combine(seed ^ 0x5eed5a4dULL, point));
}

int shard_of_point(std::uint64_t seed, std::size_t point, int shard_count) {
  if (shard_count <= 1) return 0;
  return static_cast<int>(point_hash(seed, point) % static_cast<std::uint32_t>(shard_count));
}

std::int64_t TransferDataset::local_training_sample(std::uint64_t global) const {
  const auto k = static_cast<std::uint64_t>(outgoing);
  const std::uint64_t point = global / k;
  const auto it = std::lower_bound(training_points.begin(), training_points.end(), point);
  if (it == training_points.end() || *it != point) return -1;
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(it - training_points.begin()) * k + global % k);
}

namespace {

// Every (1 / fraction)-th point of the scene, deterministic, is held out for
// validation; 0 = none.
std::size_t validation_stride(const DatasetSettings& s) {
  return s.validation_fraction > 0 ? std::max<std::size_t>(2, static_cast<std::size_t>(std::lround(1.0 / s.validation_fraction))) : 0;
}

std::vector<int> points_of_meshes(const engine::scene::SceneAssets& assets, const DatasetSettings& s) {
  const std::size_t mesh_count = assets.meshes.size();
  std::vector<double> area(mesh_count, 0.0);
  std::vector<std::size_t> vertices(mesh_count);
  for (std::size_t m = 0; m < mesh_count; ++m) {
    const auto& mesh = *assets.meshes[m];
    for (const glm::uvec3& t : mesh.triangles)
      area[m] += 0.5 * glm::length(glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]));
    vertices[m] = mesh.positions.size();
  }
  return points_per_mesh(area, vertices, s);
}

struct PointResult {
  std::vector<TransferSample> samples;
  std::vector<float> targets;
};

PointResult sample_point(const MeshTransfer& transfer, std::uint32_t mesh, std::size_t global, const DatasetSettings& s) {
  const int K = s.outgoing_per_point;
  engine::math::Pcg32 rng = engine::math::make_rng(s.seed, global, 0);
  const SurfacePoint sp = transfer.sample_point(rng);
  std::vector<glm::vec3> wo(static_cast<std::size_t>(K));
  for (auto& w : wo) w = MeshTransfer::sample_outgoing(sp, rng);
  PointResult r;
  r.targets.resize(static_cast<std::size_t>(K) * kTransferValues);
  transfer.estimate(sp, wo, s.rays, rng, r.targets);
  if (s.demodulate) {
    const glm::vec3 d = model::demodulation(sp.brdf.base_color);
    for (std::size_t j = 0; j < wo.size(); ++j)
      for (int c = 0; c < 3; ++c)
        for (int k = 0; k < engine::math::kShCount; ++k) r.targets[j * kTransferValues + static_cast<std::size_t>(c * engine::math::kShCount + k)] /= d[c];
  }
  for (const glm::vec3& w : wo) r.samples.push_back({mesh, sp.triangle, sp.barycentric, sp.shading_normal, w, sp.brdf.base_color});
  return r;
}

}  // namespace

TransferDataset generate_dataset(const engine::scene::SceneAssets& assets, const DatasetSettings& s,
                                 const std::function<void(std::size_t, std::size_t)>& progress, DatasetShard shard) {
  if (shard.count < 1 || shard.rank < 0 || shard.rank >= shard.count) throw std::invalid_argument("generate_dataset: bad shard");
  const auto start = std::chrono::steady_clock::now();
  const std::size_t mesh_count = assets.meshes.size();
  const std::vector<int> points = points_of_meshes(assets, s);
  // Points are numbered over the whole scene, mesh after mesh.
  std::vector<std::size_t> first(mesh_count + 1, 0);
  for (std::size_t m = 0; m < mesh_count; ++m) first[m + 1] = first[m] + static_cast<std::size_t>(points[m]);
  const std::size_t total_points = first[mesh_count];
  std::vector<std::size_t> mine;  // this shard's points, ascending
  for (std::size_t p = 0; p < total_points; ++p)
    if (shard_of_point(s.seed, p, shard.count) == shard.rank) mine.push_back(p);

  // A mesh's tracer lives from the first round that samples it to its last
  // (points run mesh after mesh), so only a round's few meshes are held at once.
  const auto mesh_of = [&](std::size_t p) {
    return static_cast<std::size_t>(std::upper_bound(first.begin(), first.end(), p) - first.begin() - 1);
  };
  std::vector<std::unique_ptr<engine::rt::RtScene>> tracers(mesh_count);
  std::vector<std::unique_ptr<MeshTransfer>> transfers(mesh_count);

  // Round r traces this shard's points among the scene's r-th hundredth, so
  // every rank passes its rounds at about the same time.
  std::vector<PointResult> results(mine.size());
  for (int round = 0; round < kSamplingRounds; ++round) {
    const std::size_t lo = total_points * static_cast<std::size_t>(round) / kSamplingRounds;
    const std::size_t hi = total_points * static_cast<std::size_t>(round + 1) / kSamplingRounds;
    const auto b = static_cast<int>(std::lower_bound(mine.begin(), mine.end(), lo) - mine.begin());
    const auto e = static_cast<int>(std::lower_bound(mine.begin(), mine.end(), hi) - mine.begin());
    for (int i = b; i < e; ++i) {
      const std::size_t m = mesh_of(mine[static_cast<std::size_t>(i)]);
      if (transfers[m]) continue;
      tracers[m] = make_object_tracer(assets, static_cast<std::uint32_t>(m));
      transfers[m] = std::make_unique<MeshTransfer>(
          *tracers[m], *assets.meshes[m], assets,
          s.visibility_fraction * glm::length(assets.meshes[m]->bounds_max - assets.meshes[m]->bounds_min));
    }
    engine::jobs::parallel_for(b, e, 4, [&](int pb, int pe) {
      for (int i = pb; i < pe; ++i) {
        const std::size_t p = mine[static_cast<std::size_t>(i)];
        const std::size_t m = mesh_of(p);
        results[static_cast<std::size_t>(i)] = sample_point(*transfers[m], static_cast<std::uint32_t>(m), p, s);
      }
    });
    for (std::size_t m = 0; m < mesh_count; ++m)
      if (transfers[m] && first[m + 1] <= hi) transfers[m].reset(), tracers[m].reset();  // its last point is traced
    if (progress) progress(static_cast<std::size_t>(e), mine.size());
  }

  TransferDataset d;
  d.demodulated = s.demodulate;
  d.outgoing = s.outgoing_per_point;
  d.shard = shard;
  const std::size_t stride = validation_stride(s);
  const auto is_validation = [&](std::size_t p) { return stride && p % stride == stride - 1; };
  for (int pass = 0; pass < 2; ++pass)  // training points first, then validation
    for (std::size_t i = 0; i < mine.size(); ++i) {
      const std::size_t p = mine[i];
      if (is_validation(p) != (pass == 1)) continue;
      if (pass == 0) {
        d.training_points.push_back(p - (stride ? p / stride : 0));
        d.training_point_hashes.push_back(point_hash(s.seed, p));
      }
      d.samples.insert(d.samples.end(), results[i].samples.begin(), results[i].samples.end());
      d.targets.insert(d.targets.end(), results[i].targets.begin(), results[i].targets.end());
    }
  d.training_count = d.training_points.size() * static_cast<std::size_t>(s.outgoing_per_point);
  const std::size_t all_training_points = total_points - (stride ? total_points / stride : 0);
  d.all_training_samples = all_training_points * static_cast<std::uint64_t>(s.outgoing_per_point);
  d.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return d;
}

}  // namespace transgi::bake
