#include "engine/render/path_tracer.h"

#include <atomic>
#include <chrono>
#include <cmath>

#include "engine/jobs/parallel_for.h"
#include "engine/math/sampling.h"
#include "engine/render/surface.h"

namespace engine::render {

namespace {
bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
float max_component(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
bool black(const glm::vec3& v) { return v.x <= 0 && v.y <= 0 && v.z <= 0; }
}  // namespace

const char* pass_name(Pass p) {
  switch (p) {
    case Pass::Direct: return "direct";
    case Pass::Gi: return "gi";
    case Pass::Albedo: return "albedo";
    case Pass::Textured: return "textured";
    default: return "full";
  }
}

PathTracer::PathTracer(const rt::RtScene& scene, const LightSet& lights, CameraRays camera, int width, int height,
                       PathTracerSettings settings)
    : scene_(scene),
      lights_(lights),
      camera_(camera),
      width_(width),
      height_(height),
      settings_(settings),
      sum_full_(static_cast<std::size_t>(width) * height, glm::dvec3(0.0)),
      sum_direct_(sum_full_.size(), glm::dvec3(0.0)),
      sum_gi_(sum_full_.size(), glm::dvec3(0.0)),
      sum_albedo_(sum_full_.size(), glm::dvec3(0.0)),
      sum_textured_(sum_full_.size(), 0.0),
      sum_sq_full_(sum_full_.size(), 0.0),
      sum_sq_direct_(sum_full_.size(), 0.0),
      sum_sq_gi_(sum_full_.size(), 0.0),
      count_(sum_full_.size(), 0) {}

PathRadiance PathTracer::trace(rt::Ray ray, math::Pcg32& rng) const {
  PathRadiance L;
  glm::vec3 beta(1.0f);
  float prev_bsdf_pdf = 0.0f;
  const scene::Environment* env = lights_.environment();
  // Light reaching scattering vertex k straight from an emitter is "direct"
  // when k == 0 (the camera-visible point); emission seen by the camera is
  // direct too. emitter_vertex = index of the vertex whose incoming light it is + 1.
  auto add = [&](const glm::vec3& c, int emitter_vertex) {
    L.full += c;
    (emitter_vertex <= 1 ? L.direct : L.gi) += c;
  };

  for (int depth = 0;; ++depth) {
    rt::Hit hit;
    if (!scene_.intersect(ray, hit)) {
      // The camera sees the background (with its sun disk, if the light set
      // split the sun out); bounces see the environment that lights.
      if (const scene::Environment* seen = depth == 0 ? lights_.background() : env) {
        const glm::vec3 le = seen->radiance(ray.direction);
        const float w = depth == 0 ? 1.0f : math::power_heuristic(prev_bsdf_pdf, lights_.pdf_environment(ray.direction));
        add(beta * le * w, depth);
      }
      break;
    }
    const Surface s = make_surface(scene_, hit, ray.direction);
    if (depth == 0) {
      L.albedo = s.brdf.base_color;
      L.textured = scene_.assets()->materials[s.material].is_textured_or_coloured() ? 1.0f : 0.0f;
    }
    if (!black(s.emission)) {
      float w = 1.0f;
      if (depth > 0) {
        const float light_pdf = lights_.pdf_area_light(hit.entity, hit.primitive, ray.direction, hit.t, s.geometric_normal);
        w = math::power_heuristic(prev_bsdf_pdf, light_pdf);
      }
      add(beta * s.emission * w, depth);
    }
    if (depth >= settings_.max_depth) break;

    const glm::vec3 wo = s.frame.to_local(-ray.direction);
    if (wo.z <= 0) break;  // the shading normal disagrees with the view: no reflection
    const glm::vec3 origin = rt::offset_ray_origin(s.position, s.geometric_normal, scene_.offset_scale());

    // Next-event estimation.
    LightSample ls;
    const float u_sel = rng.next_float();
    const glm::vec2 u_light{rng.next_float(), rng.next_float()};
    if (lights_.sample(s.position, u_sel, u_light, ls) && glm::dot(ls.direction, s.geometric_normal) > 0) {
      const glm::vec3 wi = s.frame.to_local(ls.direction);
      const glm::vec3 f = wi.z > 0 ? material::brdf_eval(s.brdf, wo, wi) : glm::vec3(0.0f);
      if (!black(f) && !black(ls.radiance)) {
        rt::Ray shadow{origin, ls.direction, 0.0f,
                       std::isinf(ls.distance) ? std::numeric_limits<float>::infinity() : ls.distance * (1.0f - 1e-4f)};
        if (!scene_.occluded(shadow)) {
          const float w = ls.delta ? 1.0f : math::power_heuristic(ls.pdf, material::brdf_pdf(s.brdf, wo, wi));
          const glm::vec3 c = beta * f * wi.z * ls.radiance * (ls.delta ? w : w / ls.pdf);
          add(c, depth + 1);
        }
      }
    }

    // Continue the path by sampling the BRDF.
    material::BrdfSample bs;
    const glm::vec2 u_brdf{rng.next_float(), rng.next_float()};
    const float u_lobe = rng.next_float();
    if (!material::brdf_sample(s.brdf, wo, u_brdf, u_lobe, bs)) break;
    const glm::vec3 dir = s.frame.to_world(bs.wi);
    if (glm::dot(dir, s.geometric_normal) <= 0) break;
    beta *= bs.f * (bs.wi.z / bs.pdf);
    prev_bsdf_pdf = bs.pdf;
    if (depth + 1 >= settings_.roulette_start) {
      const float q = std::max(0.05f, 1.0f - max_component(beta));
      if (rng.next_float() < q) break;
      beta /= 1.0f - q;
    }
    if (black(beta)) break;
    ray = rt::Ray{origin, dir};
  }
  return L;
}

void PathTracer::add_samples(int n, const std::vector<std::uint8_t>& want) {
  std::atomic<std::uint64_t> discarded{0}, samples{0};
  jobs::parallel_for(0, height_, 1, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width_; ++x) {
        const std::size_t pixel = static_cast<std::size_t>(y) * width_ + x;
        if (!want.empty() && !want[pixel]) continue;
        const std::uint32_t first = count_[pixel];
        for (std::uint32_t s = first; s < first + static_cast<std::uint32_t>(n); ++s) {
          math::Pcg32 rng = math::make_rng(settings_.seed, pixel, static_cast<std::uint64_t>(s));
          const glm::vec2 u{rng.next_float(), rng.next_float()};
          const rt::Ray ray = camera_.generate_filtered(x, y, u, settings_.filter_width);
          const PathRadiance L = trace(ray, rng);
          if (!finite(L.full) || !finite(L.direct) || !finite(L.gi)) {
            discarded.fetch_add(1, std::memory_order_relaxed);
            continue;  // counts as a zero sample
          }
          sum_full_[pixel] += glm::dvec3(L.full);
          sum_direct_[pixel] += glm::dvec3(L.direct);
          sum_gi_[pixel] += glm::dvec3(L.gi);
          sum_albedo_[pixel] += glm::dvec3(L.albedo);
          sum_textured_[pixel] += L.textured;
          const double lf = math::luminance(L.full), ld = math::luminance(L.direct), lg = math::luminance(L.gi);
          sum_sq_full_[pixel] += lf * lf;
          sum_sq_direct_[pixel] += ld * ld;
          sum_sq_gi_[pixel] += lg * lg;
        }
        count_[pixel] = first + static_cast<std::uint32_t>(n);
        samples.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
      }
  });
  stats_.samples += samples.load();
  stats_.discarded_non_finite += discarded.load();
}

void PathTracer::render(int spp, const std::function<void(int, int)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const int target = spp_ + spp;
  const std::vector<std::uint8_t> all;
  while (spp_ < target) {
    const int batch = std::min(settings_.batch_spp, target - spp_);
    add_samples(batch, all);
    spp_ += batch;
    if (progress) progress(spp_ - (target - spp), spp);
  }
  stats_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void PathTracer::render_adaptive(const AdaptiveSampling& a, const std::function<void(int, int)>& progress) {
  if (spp_ < a.min_spp) render(a.min_spp - spp_);
  const auto start = std::chrono::steady_clock::now();
  const auto& sums = a.pass == Pass::Direct ? sum_direct_ : a.pass == Pass::Gi ? sum_gi_ : sum_full_;
  const auto& squares = a.pass == Pass::Direct ? sum_sq_direct_ : a.pass == Pass::Gi ? sum_sq_gi_ : sum_sq_full_;
  const int pixels = width_ * height_;
  std::vector<std::uint8_t> want(static_cast<std::size_t>(pixels), 0);
  for (;;) {
    double image_mean = 0;
    for (std::size_t i = 0; i < sums.size(); ++i) image_mean += math::luminance(glm::vec3(sums[i] / static_cast<double>(std::max(1u, count_[i]))));
    image_mean /= std::max(1, pixels);
    const double floor = std::max(1e-12, a.floor * image_mean);
    int open = 0;
    for (std::size_t i = 0; i < sums.size(); ++i) {
      const double n = static_cast<double>(std::max(1u, count_[i]));
      const double mean = math::luminance(glm::vec3(sums[i] / n));
      const double variance = std::max(0.0, squares[i] / n - mean * mean) * n / std::max(1.0, n - 1);
      const double error = std::sqrt(variance / n) / std::max(std::abs(mean), floor);
      want[i] = error > a.target_error && count_[i] < static_cast<std::uint32_t>(a.max_spp) ? 1 : 0;
      open += want[i];
    }
    if (progress) progress(pixels - open, pixels);
    if (open == 0) break;
    add_samples(a.round_spp, want);
  }
  stats_.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double PathTracer::mean_samples_per_pixel() const {
  double sum = 0;
  for (std::uint32_t c : count_) sum += c;
  return count_.empty() ? 0.0 : sum / static_cast<double>(count_.size());
}

image::ImageRGB PathTracer::image(Pass pass) const {
  if (pass == Pass::Textured) {
    image::ImageRGB out(width_, height_);
    for (std::size_t i = 0; i < sum_textured_.size(); ++i)
      out.pixels[i] = glm::vec3(count_[i] > 0 ? static_cast<float>(sum_textured_[i] / count_[i]) : 0.0f);
    return out;
  }
  const auto& sums = pass == Pass::Direct ? sum_direct_ : pass == Pass::Gi ? sum_gi_ : pass == Pass::Albedo ? sum_albedo_ : sum_full_;
  image::ImageRGB out(width_, height_);
  for (std::size_t i = 0; i < sums.size(); ++i) out.pixels[i] = count_[i] > 0 ? glm::vec3(sums[i] / static_cast<double>(count_[i])) : glm::vec3(0.0f);
  return out;
}

image::ImageRGB render_direct_light(const rt::RtScene& scene, const LightSet& lights, const CameraRays& camera, int width,
                                    int height, int spp, std::uint64_t seed) {
  PathTracer direct(scene, lights, camera, width, height, PathTracerSettings{.max_depth = 1, .seed = seed});
  direct.render(spp);
  return direct.image(Pass::Direct);
}

}  // namespace engine::render
