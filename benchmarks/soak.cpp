// Soak with many moving entities (issue 13, item 4): not a timed test but a
// measurement, recorded in docs/reliability.md.
//
//   engine_soak [--entities 10000] [--frames 10000] [--churn 1000]
//
// Phase 1: `entities` rigid cubes all move and turn every frame for `frames`
// frames; per frame, the Embree top-level sync's time (the rt::sync_scene
// system) against the whole frame; resident memory every 1,000 frames.
// Phase 2: as many frames again, despawning `churn` random cubes and spawning
// as many new ones every frame; resident memory every 1,000 frames.
// Memory must stay flat: the last reading within 2 % of the one at frame
// 1,000 (the first after warm-up). Exit status 1 if it does not.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "engine/app/app.h"
#include "engine/core/args.h"
#include "engine/math/rng.h"
#include "engine/rt/rt_plugin.h"
#include "engine/scene/components.h"
#include "engine/scene/procedural.h"

using namespace engine;

namespace {

double rss_mb() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return static_cast<double>(resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1 << 20);
}

double sync_ms(app::App& app) {
  for (const auto& s : app.schedule().stats())
    if (s.name == "rt::sync_scene") return s.last_ms;
  return 0.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const core::Args args("soak", std::vector<std::string>(argv + 1, argv + argc), {"entities", "frames", "churn", "threads"});
    const int entities = static_cast<int>(args.integer("entities", 1, 1'000'000, 10'000));
    const int frames = static_cast<int>(args.integer("frames", 1000, 10'000'000, 10'000));
    const int churn = static_cast<int>(args.integer("churn", 0, 1'000'000, 1'000));
    const int threads = static_cast<int>(args.integer("threads", 0, 1024, 0));

    app::App app(app::AppOptions{.jobs = {.threads = threads}});
    auto& w = app.world();
    scene::SceneAssets assets;
    assets.generation = scene::next_scene_generation();
    assets.meshes = {std::make_shared<scene::MeshAsset>(scene::make_box(glm::vec3(0.2f), false, 0))};
    assets.materials.resize(1);
    w.insert_resource<scene::SceneAssets>(std::move(assets));
    app.add_plugin<rt::RtPlugin>();

    math::Pcg32 rng(2026, 11);
    std::vector<ecs::Entity> cubes;
    std::vector<glm::vec3> home;
    auto spawn = [&] {
      const ecs::Entity e = w.spawn();
      const glm::vec3 at(100.0f * rng.next_float(), 10.0f * rng.next_float(), 100.0f * rng.next_float());
      w.emplace<transform::Transform>(e, transform::Transform::from_translation(at));
      w.emplace<scene::MeshInstance>(e, scene::MeshInstance{0});
      cubes.push_back(e);
      home.push_back(at);
    };
    for (int i = 0; i < entities; ++i) spawn();

    std::printf("soak: %d entities, %d frames moving, then %d frames spawning and despawning %d a frame, %d threads\n", entities,
                frames, frames, churn, threads);
    std::printf("phase,frame,rss_mb,median_frame_ms,median_sync_ms\n");
    bool flat = true;
    for (int phase = 1; phase <= 2; ++phase) {
      double rss_first = 0;
      std::vector<double> frame_ms, sync;
      for (int f = 1; f <= frames; ++f) {
        if (phase == 2) {
          for (int k = 0; k < churn && !cubes.empty(); ++k) {
            const std::size_t i = static_cast<std::size_t>(rng.next_float() * static_cast<float>(cubes.size())) % cubes.size();
            w.despawn(cubes[i]);
            cubes[i] = cubes.back();
            home[i] = home.back();
            cubes.pop_back();
            home.pop_back();
          }
          for (int k = 0; k < churn; ++k) spawn();
        }
        const float t = 0.016f * static_cast<float>(f);
        for (std::size_t i = 0; i < cubes.size(); ++i) {
          auto& tr = w.get_mut<transform::Transform>(cubes[i]);
          tr.translation = home[i] + glm::vec3(std::sin(t + static_cast<float>(i)), 0.0f, std::cos(t + static_cast<float>(i)));
          tr.rotation = glm::angleAxis(t + static_cast<float>(i % 7), glm::vec3(0, 1, 0));
        }
        const auto t0 = std::chrono::steady_clock::now();
        app.jobs().run([&] { app.update(); });
        frame_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        sync.push_back(sync_ms(app));
        if (f % 1000 == 0) {
          const double rss = rss_mb();
          if (f == 1000) rss_first = rss;
          std::printf("%d,%d,%.1f,%.3f,%.3f\n", phase, f, rss, median(frame_ms), median(sync));
          std::fflush(stdout);
          frame_ms.clear();
          sync.clear();
          if (f == frames && rss > rss_first * 1.02) {
            std::printf("phase %d: resident memory grew %.1f -> %.1f MB (more than 2 %%)\n", phase, rss_first, rss);
            flat = false;
          }
        }
      }
    }
    std::printf("%s\n", flat ? "memory flat in both phases (within 2 % of frame 1,000)" : "MEMORY GREW");
    return flat ? 0 : 1;
  } catch (const core::UsageError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
