#include "shading/transfer_renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>

#include <glm/gtc/quaternion.hpp>

#include "bake/transfer.h"
#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/render/surface.h"
#include "engine/rt/ray.h"
#include "shading/gbuffer.h"
#include "shading/transfer_inference.h"

namespace transgi::shading {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

using Sample = GSample;

constexpr std::array<int, 3> kMapCoefficients = {0, 2, 6};  // (0,0), (1,0), (2,0)

}  // namespace

bool is_mirror(const engine::material::BrdfParams& brdf, const MirrorRay& mirror) {
  return mirror.max_roughness >= 0 && brdf.metallic >= 0.5f && brdf.roughness <= mirror.max_roughness;
}

namespace {

// Irradiance at a reflection ray's hit from light_samples next-event
// samples of the lights (sky, emitters and punctual lights alike).
glm::vec3 sampled_irradiance(const engine::rt::RtScene& scene, const engine::render::Surface& s,
                             const engine::render::LightSet* lights, int light_samples, engine::math::Pcg32& rng) {
  using namespace engine;
  if (!lights || light_samples <= 0) return glm::vec3(0.0f);
  const glm::vec3 origin = rt::offset_ray_origin(s.position, s.geometric_normal, scene.offset_scale());
  glm::vec3 direct(0.0f);
  for (int k = 0; k < light_samples; ++k) {
    render::LightSample ls;
    const float u_sel = rng.next_float();
    const glm::vec2 u{rng.next_float(), rng.next_float()};
    if (!lights->sample(s.position, u_sel, u, ls) || glm::dot(ls.direction, s.geometric_normal) <= 0) continue;
    const float cos_i = glm::dot(ls.direction, s.shading_normal);
    if (cos_i <= 0) continue;
    const float tmax = std::isinf(ls.distance) ? std::numeric_limits<float>::infinity() : ls.distance * (1.0f - 1e-4f);
    if (scene.occluded(rt::Ray{origin, ls.direction, 0.0f, tmax})) continue;
    direct += ls.radiance * cos_i / (ls.delta ? 1.0f : ls.pdf);
  }
  return direct / static_cast<float>(light_samples);
}

// The probes' irradiance at a hit (light_at) plus light_samples next-event
// samples of the lights: the mirror path's estimate.
HitIrradiance probe_and_sampled_irradiance(const engine::rt::RtScene& scene, const LightAt& light_at,
                                           const engine::render::LightSet* lights, int light_samples,
                                           engine::math::Pcg32& rng) {
  return [&scene, &light_at, lights, light_samples, &rng](const engine::render::Surface& s) {
    float sh[75];
    light_at(s.position, s.shading_normal, sh);
    return sh_irradiance(sh, s.shading_normal) + sampled_irradiance(scene, s, lights, light_samples, rng);
  };
}

}  // namespace

bool reflection_ray(const engine::rt::RtScene& scene, const GSample& smp, const glm::vec3& wi, engine::rt::Ray& ray) {
  if (glm::dot(wi, smp.geometric_normal) <= 0) return false;
  ray = engine::rt::Ray{engine::rt::offset_ray_origin(smp.position, smp.geometric_normal, scene.offset_scale()), wi};
  return true;
}

std::optional<ReflectedLight> reflected_without_irradiance(const engine::render::Surface* hit, const glm::vec3& wi,
                                                           const engine::scene::Environment* sky) {
  if (!hit) return ReflectedLight{sky ? sky->radiance(wi) : glm::vec3(0.0f), glm::vec3(0.0f)};
  if (hit->emission.r > 0 || hit->emission.g > 0 || hit->emission.b > 0) return ReflectedLight{hit->emission, glm::vec3(0.0f)};
  if (engine::material::diffuse_albedo(hit->brdf) == glm::vec3(0.0f)) return ReflectedLight{};
  return std::nullopt;
}

glm::vec3 reflected_gi(const engine::render::Surface& hit, const glm::vec3& wi, const glm::vec3& irradiance) {
  const float cos_o = std::clamp(-glm::dot(hit.shading_normal, wi), 0.0f, 1.0f);
  return engine::material::directional_albedo(hit.brdf, cos_o) * engine::math::kInvPi * glm::max(irradiance, glm::vec3(0.0f));
}

ReflectedLight reflected_light(const engine::rt::RtScene& scene, const GSample& smp, const glm::vec3& wi,
                               const engine::scene::Environment* sky, const HitIrradiance& irradiance) {
  using namespace engine;
  rt::Ray ray;
  if (!reflection_ray(scene, smp, wi, ray)) return {};
  rt::Hit hit;
  if (!scene.intersect(ray, hit)) return *reflected_without_irradiance(nullptr, wi, sky);
  const render::Surface s = render::make_surface(scene, hit, wi);
  if (const std::optional<ReflectedLight> r = reflected_without_irradiance(&s, wi, sky)) return *r;
  return {glm::vec3(0.0f), reflected_gi(s, wi, irradiance(s))};
}

bool sample_reflection(const GSample& smp, bool mirror, glm::vec2 u, glm::vec3& wi_world, glm::vec3& weight) {
  using namespace engine;
  const bool metal = smp.brdf.metallic >= 0.5f;
  const glm::vec3 f0 = metal ? smp.brdf.base_color : glm::min(material::kDielectricF0 * smp.brdf.specular_color, glm::vec3(1.0f));
  const float layer = metal ? 1.0f : smp.brdf.specular;
  if (mirror) {
    const glm::vec3 n = smp.normal_world, wo = smp.wo_world;
    const float cos_o = glm::dot(n, wo);
    if (cos_o <= 0) return false;
    wi_world = glm::normalize(2.0f * cos_o * n - wo);
    weight = layer * material::schlick_fresnel(f0, cos_o);
    return true;
  }
  const math::Frame frame = math::Frame::from_normal(smp.normal_world);
  const glm::vec3 wo = frame.to_local(smp.wo_world);
  if (wo.z <= 0) return false;
  const float alpha = std::max(smp.brdf.roughness * smp.brdf.roughness, material::kMinAlpha);
  const glm::vec3 h = material::sample_ggx_vndf(alpha, wo, u);
  const float wo_h = glm::dot(wo, h);
  const glm::vec3 wi = 2.0f * wo_h * h - wo;
  if (wi.z <= 0 || wo_h <= 0) return false;
  // Sampling the visible normals, f cos / pdf = F(wo.h) G2(wo, wi) / G1(wo),
  // which separable Smith makes G1(wi).
  weight = layer * material::schlick_fresnel(f0, wo_h) * material::smith_g1(alpha, wi.z);
  wi_world = glm::normalize(frame.to_world(wi));
  return true;
}

ReflectedLight shade_mirror(const engine::rt::RtScene& scene, const GSample& smp, const LightAt& light_at,
                            const engine::render::LightSet* lights, const MirrorRay& mirror, engine::math::Pcg32& rng) {
  return shade_glossy(scene, smp, light_at, lights, mirror, glm::vec2(0.0f), rng, true);
}

ReflectedLight shade_glossy(const engine::rt::RtScene& scene, const GSample& smp, const LightAt& light_at,
                            const engine::render::LightSet* lights, const MirrorRay& mirror, glm::vec2 u,
                            engine::math::Pcg32& rng, bool mirror_direction) {
  glm::vec3 wi, weight;
  if (!sample_reflection(smp, mirror_direction, u, wi, weight)) return {};
  // The mirror's light samples: with one, the choice of light left the
  // reflections speckled after the antialiasing's 16-phase mean
  // (docs/image-quality.md, "Glossy metals").
  const ReflectedLight r =
      reflected_light(scene, smp, wi, nullptr, probe_and_sampled_irradiance(scene, light_at, lights, mirror.light_samples, rng));
  return {weight * r.direct, weight * r.gi};
}

glm::vec2 gbuffer_subpixel(std::uint64_t pattern_seed, std::size_t pixel, std::uint64_t sample) {
  engine::math::Pcg32 rng = engine::math::make_rng(pattern_seed, pixel, 0x5EEDull);
  const glm::vec2 offset{rng.next_float(), rng.next_float()};
  return engine::math::r2_point(sample, offset);
}

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
  const float spread = s.texture_filtering ? camera.pixel_spread() * std::exp2(s.texture_lod_bias) : 0.0f;
  jobs::parallel_for(0, height, 1, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x)
        for (int si = 0; si < s.spp; ++si) {
          const std::size_t pixel = static_cast<std::size_t>(y) * width + x;
          const glm::vec2 u = gbuffer_subpixel(
              s.pattern_seed, pixel, s.frame_index * static_cast<std::uint64_t>(s.spp) + static_cast<std::uint64_t>(si));
          const rt::Ray ray = camera.generate_filtered(x, y, u, s.filter_width);
          Sample& out = samples[pixel * static_cast<std::size_t>(s.spp) + static_cast<std::size_t>(si)];
          out = trace_gsample(scene, assets, ray, background, spread);
        }
  });
  result.timings.gbuffer_ms = ms_since(t0);

  // Samples with transfer first (they go through inference), then the rest.
  std::vector<std::size_t> hits, diffuse_only, mirrors;
  {
    std::unordered_map<engine::ecs::Entity, bool> cache;
    auto has_transfer = [&](engine::ecs::Entity e) {
      if (!s.has_transfer) return true;
      auto [it, inserted] = cache.try_emplace(e, false);
      if (inserted) it->second = s.has_transfer(e);
      return it->second;
    };
    for (std::size_t i = 0; i < n; ++i)
      if (samples[i].hit)
        (is_mirror(samples[i].brdf, s.mirror) ? mirrors : has_transfer(samples[i].entity) ? hits : diffuse_only).push_back(i);
  }
  result.inferred_samples = hits.size();
  result.mirror_samples = mirrors.size();
  result.shaded_samples = hits.size() + diffuse_only.size() + mirrors.size();
  std::vector<float> transfer(hits.size() * bake::kTransferValues, 0.0f);

  if (source == TransferSource::Network) {
    // 2. Network inputs, 3. batched inference.
    std::vector<TransferQuery> queries(hits.size());
    for (std::size_t i = 0; i < hits.size(); ++i) {
      const Sample& smp = samples[hits[i]];
      queries[i] = {smp.mesh, smp.triangle, smp.bary, smp.albedo, smp.normal_obj, smp.wo_obj};
    }
    const InferenceTimings it = infer_transfer(model, assets, queries, transfer.data());
    // A demodulated model predicts transfer over albedo: each sample's own
    // albedo, at full resolution, multiplies it back.
    if (model.demodulated)
      jobs::parallel_for<std::size_t>(0, hits.size(), 1024, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
          const glm::vec3 d = model::demodulation(samples[hits[i]].albedo);
          for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 25; ++k) transfer[i * bake::kTransferValues + static_cast<std::size_t>(c * 25 + k)] *= d[c];
        }
      });
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
                                                            model.self_masked_within(*assets.meshes[m]));
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
  // Per object: the rotation of world SH into its frame, and where its
  // transfer masks the object itself, in world units.
  struct ObjectFrame {
    math::ShRotation to_object;
    float masked_within = 0.0f;
  };
  std::unordered_map<engine::ecs::Entity, ObjectFrame> objects;
  for (std::size_t i : hits)
    if (!objects.contains(samples[i].entity)) {
      const engine::transform::Similarity& to_world = scene.instance_of(samples[i].entity)->to_world;
      objects.emplace(samples[i].entity, ObjectFrame{math::ShRotation(glm::transpose(glm::mat3_cast(to_world.rotation))),
                                                     model.self_masked_within(*assets.meshes[samples[i].mesh]) * to_world.scale});
    }
  std::vector<glm::vec3> shaded(n, glm::vec3(0.0f));
  // The contact light the probes miss (near_field.h), estimated from the
  // same world light as the shading, filtered across similar neighbours,
  // then added through each sample's diffuse albedo; the total is clamped
  // at zero, as sh_irradiance is.
  const bool with_near = s.near_field.rays > 0 && s.probe_spacing_at;
  std::vector<glm::vec3> near(with_near ? n : 0, glm::vec3(0.0f));
  // own_masked_within: where a sample's transfer masks its own object (0: shaded without one).
  const auto estimate_near = [&](std::size_t i, const float* world, float own_masked_within) {
    if (!with_near) return;
    const Sample& smp = samples[i];
    math::Pcg32 rng = math::make_rng(s.seed ^ 0x4EA2F1ull, i, 0);
    const float reach = s.near_field.reach_cells * s.probe_spacing_at(smp.position);
    near[i] = near_field_irradiance(scene, s.lights, smp, world, reach, own_masked_within, s.near_field.rays, light_at, rng);
  };
  const std::size_t grain = with_near ? 16 : 256;
  jobs::parallel_for<std::size_t>(0, hits.size(), grain, [&](std::size_t b, std::size_t e) {
    float world[75], object[75];
    for (std::size_t j = b; j < e; ++j) {
      const Sample& smp = samples[hits[j]];
      light_at(smp.position, smp.normal_world, world);
      const ObjectFrame& frame = objects.at(smp.entity);
      const math::ShRotation& rot = frame.to_object;
      for (int c = 0; c < 3; ++c) rot.apply(world + c * 25, object + c * 25);
      ShRgb light;
      std::copy(object, object + 75, light.begin());
      shaded[hits[j]] = shade(light, transfer.data() + j * bake::kTransferValues);
      estimate_near(hits[j], world, frame.masked_within);
    }
  });
  jobs::parallel_for<std::size_t>(0, diffuse_only.size(), grain, [&](std::size_t b, std::size_t e) {
    float world[75];
    for (std::size_t j = b; j < e; ++j) {
      const Sample& smp = samples[diffuse_only[j]];
      light_at(smp.position, smp.normal_world, world);
      shaded[diffuse_only[j]] = smp.diffuse * math::kInvPi * sh_irradiance(world, smp.normal_world);
      estimate_near(diffuse_only[j], world, 0.0f);
    }
  });
  if (with_near) {
    std::vector<glm::vec4> guide(n, glm::vec4(0.0f));
    for (std::size_t i = 0; i < n; ++i)
      if (samples[i].hit) guide[i] = glm::vec4(samples[i].normal_world, std::max(samples[i].depth, 1e-30f));
    const std::vector<glm::vec3> filtered = filter_near_field(guide, width, height, s.spp, near, s.near_field.filter_radius);
    for (const std::vector<std::size_t>* which : {&hits, &diffuse_only})
      for (const std::size_t i : *which)
        shaded[i] = glm::max(shaded[i] + samples[i].diffuse * math::kInvPi * filtered[i], glm::vec3(0.0f));
  }
  jobs::parallel_for<std::size_t>(0, mirrors.size(), 64, [&](std::size_t b, std::size_t e) {
    for (std::size_t j = b; j < e; ++j) {
      math::Pcg32 rng = math::make_rng(s.seed ^ 0x4D1Bull, mirrors[j], 0);
      shaded[mirrors[j]] = shade_mirror(scene, samples[mirrors[j]], light_at, s.lights, s.mirror, rng).gi;
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
