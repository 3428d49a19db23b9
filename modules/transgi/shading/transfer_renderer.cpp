#include "shading/transfer_renderer.h"

#include <chrono>
#include <mutex>

#include <glm/gtc/quaternion.hpp>

#include "bake/transfer.h"
#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/render/surface.h"
#include "shading/gbuffer.h"
#include "shading/transfer_inference.h"

namespace transgi::shading {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

using Sample = GSample;

constexpr std::array<int, 3> kMapCoefficients = {0, 2, 6};  // (0,0), (1,0), (2,0)

}  // namespace

TransferRenderResult render_transfer(const engine::rt::RtScene& scene, const engine::scene::SceneAssets& assets,
                                     const model::TransferModel& model, const engine::render::CameraRays& camera,
                                     int width, int height, const LightAt& light_at,
                                     const engine::scene::Environment* background, TransferSource source,
                                     const TransferRenderSettings& s) {
  using namespace engine;
  TransferRenderResult result;
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  const std::size_t n = pixels * static_cast<std::size_t>(s.spp);

  // 1. G-buffer: one filtered primary ray per sample.
  auto t0 = Clock::now();
  std::vector<Sample> samples(n);
  jobs::parallel_for(0, height, 1, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x)
        for (int si = 0; si < s.spp; ++si) {
          const std::size_t pixel = static_cast<std::size_t>(y) * width + x;
          math::Pcg32 rng = math::make_rng(s.seed, pixel, static_cast<std::uint64_t>(si));
          const glm::vec2 u(rng.next_float(), rng.next_float());
          const rt::Ray ray = camera.generate_filtered(x, y, u, s.filter_width);
          Sample& out = samples[pixel * static_cast<std::size_t>(s.spp) + static_cast<std::size_t>(si)];
          out = trace_gsample(scene, assets, ray, background);
        }
  });
  result.timings.gbuffer_ms = ms_since(t0);

  // Samples with transfer first (they go through inference), then the rest.
  std::vector<std::size_t> hits, diffuse_only;
  {
    std::unordered_map<engine::ecs::Entity, bool> cache;
    auto has_transfer = [&](engine::ecs::Entity e) {
      if (!s.has_transfer) return true;
      auto [it, inserted] = cache.try_emplace(e, false);
      if (inserted) it->second = s.has_transfer(e);
      return it->second;
    };
    for (std::size_t i = 0; i < n; ++i)
      if (samples[i].hit) (has_transfer(samples[i].entity) ? hits : diffuse_only).push_back(i);
  }
  result.inferred_samples = hits.size();
  result.shaded_samples = hits.size() + diffuse_only.size();
  std::vector<float> transfer(hits.size() * bake::kTransferValues, 0.0f);

  if (source == TransferSource::Network) {
    // 2. Network inputs, 3. batched inference.
    std::vector<TransferQuery> queries(hits.size());
    for (std::size_t i = 0; i < hits.size(); ++i) {
      const Sample& smp = samples[hits[i]];
      queries[i] = {smp.mesh, smp.triangle, smp.bary, smp.albedo, smp.normal_obj, smp.wo_obj};
    }
    const InferenceTimings it = infer_transfer(model, assets, queries, transfer.data());
    result.timings.inputs_ms = it.inputs_ms;
    result.timings.inference_ms = it.inference_ms;
  } else {
    // Ground truth: integrate each sample's transfer with the bake's estimator.
    t0 = Clock::now();
    std::vector<std::unique_ptr<engine::rt::RtScene>> tracers(assets.meshes.size());
    std::vector<std::unique_ptr<bake::MeshTransfer>> transfers(assets.meshes.size());
    for (std::size_t i : hits) {
      const std::uint32_t m = samples[i].mesh;
      if (!transfers[m]) {
        tracers[m] = bake::make_object_tracer(assets, m);
        transfers[m] = std::make_unique<bake::MeshTransfer>(*tracers[m], *assets.meshes[m], assets,
                                                            bake::default_visibility_distance(*assets.meshes[m]));
      }
    }
    jobs::parallel_for<std::size_t>(0, hits.size(), 16, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const Sample& smp = samples[hits[i]];
        bake::SurfacePoint p = transfers[smp.mesh]->point_at(smp.triangle, smp.bary);
        // Seen from the back of a two-sided surface: shade the side facing the viewer.
        if (glm::dot(p.shading_normal, smp.normal_obj) < 0) {
          p.shading_normal = -p.shading_normal;
          p.geometric_normal = -p.geometric_normal;
        }
        math::Pcg32 rng = math::make_rng(s.seed ^ 0x67ull, hits[i], 0);
        transfers[smp.mesh]->estimate(p, std::span(&smp.wo_obj, 1), s.ground_truth_rays, rng,
                                      std::span(transfer).subspan(i * bake::kTransferValues, bake::kTransferValues));
      }
    });
    result.timings.inference_ms = ms_since(t0);
  }

  // 4. Light at each sample (world SH), rotated into its object's frame, dotted with the transfer.
  t0 = Clock::now();
  std::unordered_map<engine::ecs::Entity, math::ShRotation> to_object;
  for (std::size_t i : hits)
    if (!to_object.contains(samples[i].entity))
      to_object.emplace(samples[i].entity,
                        math::ShRotation(glm::transpose(glm::mat3_cast(scene.instance_of(samples[i].entity)->to_world.rotation))));
  std::vector<glm::vec3> shaded(n, glm::vec3(0.0f));
  jobs::parallel_for<std::size_t>(0, hits.size(), 256, [&](std::size_t b, std::size_t e) {
    float world[75], object[75];
    for (std::size_t j = b; j < e; ++j) {
      const Sample& smp = samples[hits[j]];
      light_at(smp.position, smp.normal_world, world);
      const math::ShRotation& rot = to_object.at(smp.entity);
      for (int c = 0; c < 3; ++c) rot.apply(world + c * 25, object + c * 25);
      ShRgb light;
      std::copy(object, object + 75, light.begin());
      shaded[hits[j]] = shade(light, transfer.data() + j * bake::kTransferValues);
    }
  });
  jobs::parallel_for<std::size_t>(0, diffuse_only.size(), 256, [&](std::size_t b, std::size_t e) {
    float world[75];
    for (std::size_t j = b; j < e; ++j) {
      const Sample& smp = samples[diffuse_only[j]];
      light_at(smp.position, smp.normal_world, world);
      shaded[diffuse_only[j]] = smp.diffuse * math::kInvPi * sh_irradiance(world, smp.normal_world);
    }
  });
  result.light_ms = ms_since(t0);
  t0 = Clock::now();
  result.image = image::ImageRGB(width, height);
  for (auto& m : result.coefficient_maps) m = image::ImageRGB(width, height);
  std::vector<std::size_t> hit_slot(n, SIZE_MAX);
  for (std::size_t j = 0; j < hits.size(); ++j) hit_slot[hits[j]] = j;
  const float inv = 1.0f / static_cast<float>(s.spp);
  for (std::size_t p = 0; p < pixels; ++p) {
    glm::vec3 sum(0.0f);
    std::array<float, 3> maps{};
    for (int si = 0; si < s.spp; ++si) {
      const std::size_t i = p * static_cast<std::size_t>(s.spp) + static_cast<std::size_t>(si);
      if (!samples[i].hit) {
        sum += samples[i].background;
        continue;
      }
      sum += shaded[i];
      if (hit_slot[i] == SIZE_MAX) continue;  // no transfer (diffuse fallback)
      const float* t = transfer.data() + hit_slot[i] * bake::kTransferValues;
      for (std::size_t m = 0; m < 3; ++m) {
        const int k = kMapCoefficients[m];
        maps[m] += 0.2126f * t[k] + 0.7152f * t[25 + k] + 0.0722f * t[50 + k];
      }
    }
    result.image.pixels[p] = sum * inv;
    for (std::size_t m = 0; m < 3; ++m) result.coefficient_maps[m].pixels[p] = glm::vec3(maps[m] * inv);
  }
  result.timings.shading_ms = ms_since(t0);
  return result;
}

LightAt constant_light(const ShRgb& world_light) {
  return [world_light](const glm::vec3&, const glm::vec3&, float* out) { std::copy(world_light.begin(), world_light.end(), out); };
}

}  // namespace transgi::shading
