// ProbeField::replace_with_oracle: the probes' light path-traced (error
// decomposition, issue 14 item 2). Kept apart from the frame loop.
#include <cmath>

#include "engine/core/progress.h"
#include "engine/jobs/parallel_for.h"
#include "engine/math/rng.h"
#include "engine/render/path_tracer.h"
#include "engine/render/surface.h"
#include "probes/probe_field.h"

namespace transgi::probes {

void ProbeField::replace_with_oracle(const engine::rt::RtScene& scene, const engine::render::LightSet& lights, int rays_per_texel,
                                     std::uint64_t seed) {
  using namespace engine;
  const MapLayout& layout = settings_.map;
  const int texels = layout.texel_count(), probes = grid_.count();
  const render::PathTracer tracer(scene, lights, render::CameraRays(scene::Camera{}, transform::Similarity{}, 1, 1), 1, 1,
                                  render::PathTracerSettings{.seed = seed});
  const int side = std::max(1, static_cast<int>(std::lround(std::sqrt(static_cast<double>(rays_per_texel)))));
  core::ProgressBar bar("oracle probes (" + std::to_string(side * side) + " paths per texel)", static_cast<std::uint64_t>(probes));
  for (int q = 0; q < probes; ++q) {
    bar.update(static_cast<std::uint64_t>(q));
    if (!probes_.usable[static_cast<std::size_t>(q)]) continue;
    ProbeMapState& st = probes_.maps[static_cast<std::size_t>(q)];
    st.reset(texels, depth_unit());
    std::vector<glm::vec3> radiance(static_cast<std::size_t>(texels));
    const glm::vec3 origin = grid_.position(q);
    jobs::parallel_for(0, texels, 16, [&](int b, int e) {
      for (int t = b; t < e; ++t) {
        const int x = t % layout.width, y = t / layout.width;
        // Stratified over the texel, uniform in solid angle (cos theta uniform in v).
        const double c0 = std::cos(M_PI * y / layout.height), c1 = std::cos(M_PI * (y + 1) / layout.height);
        glm::dvec3 sum(0.0);
        double d1 = 0, d2 = 0;
        int hits = 0;
        for (int i = 0; i < side * side; ++i) {
          math::Pcg32 rng = math::make_rng(seed, static_cast<std::uint64_t>(q) * texels + t, static_cast<std::uint64_t>(i));
          const double u = (x + (i % side + static_cast<double>(rng.next_float())) / side) / layout.width;
          const double cy = c0 + (c1 - c0) * (i / side + static_cast<double>(rng.next_float())) / side;
          const double sy = std::sqrt(std::max(0.0, 1.0 - cy * cy));
          const glm::vec3 dir(static_cast<float>(std::sin(2 * M_PI * u) * sy), static_cast<float>(cy),
                              static_cast<float>(-std::cos(2 * M_PI * u) * sy));
          const rt::Ray ray{origin, dir};
          rt::Hit hit;
          if (!scene.intersect(ray, hit)) continue;  // escaped: the probes hold nothing there
          const render::Surface s = render::make_surface(scene, hit, dir);
          const render::PathRadiance L = tracer.trace(ray, rng);
          const glm::vec3 leaving = L.full - s.emission;
          if (std::isfinite(leaving.r + leaving.g + leaving.b)) sum += glm::dvec3(glm::max(leaving, glm::vec3(0.0f)));
          d1 += hit.t;
          d2 += static_cast<double>(hit.t) * hit.t;
          ++hits;
        }
        const int n = side * side;
        radiance[static_cast<std::size_t>(t)] = glm::vec3(sum / static_cast<double>(n));
        st.sampled[static_cast<std::size_t>(t)] = 1;
        if (hits > 0) {
          const double mean = d1 / hits;
          st.depth.set(static_cast<std::size_t>(t), static_cast<float>(mean), static_cast<float>(std::max(0.0, d2 / hits - mean * mean)));
        }
      }
    });
    st.frames = 1;
    float peak = 0;
    for (const glm::vec3& v : radiance) peak = std::max(peak, std::max(v.r, std::max(v.g, v.b)));
    st.radiance_scale = fitted_scale(st.radiance_scale, peak);  // the state was just reset: nothing to rescale
    for (std::size_t t = 0; t < radiance.size(); ++t) st.set_radiance(t, radiance[t]);
    projector_.project(radiance.data(), probes_.sh.data() + static_cast<std::size_t>(q) * 75);
    if (settings_.window) apply_hanning_window(probes_.sh.data() + static_cast<std::size_t>(q) * 75);
  }
  bar.finish();
}

}  // namespace transgi::probes
