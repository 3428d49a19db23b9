// Engine demo: a small solar system built from a Transform hierarchy
// (sun -> planets -> moons). Update rotates each pivot, PostUpdate propagates
// world transforms, Render draws every body's world position into a top-down
// trail image, Present writes it as a PNG. Shows the ECS, scheduler, plugins
// and transform propagation working together; prints per-system timings.
//
//   engine_demo [--frames N] [--threads T] [--out PATH]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>
#include <string_view>

#include "engine/app/app.h"
#include "engine/image/png.h"
#include "engine/transform/transform_plugin.h"

namespace {

using namespace engine;
using namespace engine::schedule;
using transform::Parent;
using transform::Transform;
using transform::WorldTransform;

struct Spin {
  float radians_per_second;
};
struct Body {
  std::uint8_t r, g, b;
  int radius_px;
};

struct DemoImage {
  image::Rgb8Image trails{512, 512};
  image::Rgb8Image frame{512, 512};
  std::string out_path;
  std::uint64_t frames_to_run = 0;
};

void spin_pivots(View<Get<Transform, const Spin>> pivots, Res<app::Time> time) {
  pivots.each([&](Transform& t, const Spin& s) {
    const float angle = s.radians_per_second * static_cast<float>(time->delta_seconds);
    t.rotation = glm::normalize(glm::angleAxis(angle, glm::vec3(0, 1, 0)) * t.rotation);
  });
}

void plot(image::Rgb8Image& img, glm::vec3 p, const Body& b, float fade) {
  const float scale = 12.0f;  // world units -> pixels
  const int cx = static_cast<int>(0.5f * static_cast<float>(img.width) + p.x * scale);
  const int cy = static_cast<int>(0.5f * static_cast<float>(img.height) + p.z * scale);
  for (int dy = -b.radius_px; dy <= b.radius_px; ++dy)
    for (int dx = -b.radius_px; dx <= b.radius_px; ++dx) {
      const int x = cx + dx, y = cy + dy;
      if (dx * dx + dy * dy > b.radius_px * b.radius_px || x < 0 || y < 0 || x >= img.width || y >= img.height)
        continue;
      std::uint8_t* px = img.at(x, y);
      px[0] = std::max(px[0], static_cast<std::uint8_t>(b.r * fade));
      px[1] = std::max(px[1], static_cast<std::uint8_t>(b.g * fade));
      px[2] = std::max(px[2], static_cast<std::uint8_t>(b.b * fade));
    }
}

void draw_bodies(View<Get<const WorldTransform, const Body>> bodies, ResMut<DemoImage> image) {
  image->frame = image->trails;
  bodies.each([&](const WorldTransform& w, const Body& b) {
    plot(image->trails, w.translation, Body{b.r, b.g, b.b, 0}, 0.45f);
    plot(image->frame, w.translation, b, 1.0f);
  });
}

void present(ResMut<DemoImage> image, Res<app::Time> time, ResMut<app::AppExit> exit) {
  if (time->frame + 1 < image->frames_to_run) return;
  image::write_png(image->out_path, image->frame);
  exit->requested = true;
}

class SolarSystemPlugin final : public app::Plugin {
 public:
  void build(app::App& app) override {
    app.add_plugin<transform::TransformPlugin>();
    app.add_system(Phase::Startup, "demo::spawn", spawn);
    app.add_system(Phase::Update, "demo::spin", spin_pivots);
    app.add_system(Phase::Render, "demo::draw", draw_bodies);
    app.add_system(Phase::Present, "demo::present", present);
  }
  [[nodiscard]] std::string_view name() const override { return "demo::SolarSystem"; }

 private:
  static void spawn(Commands& cmd) {
    const Entity sun = cmd.spawn();
    cmd.insert(sun, Transform{}).insert(sun, Body{255, 210, 60, 9});
    for (int i = 0; i < 5; ++i) {
      const float orbit = 4.0f + 3.5f * static_cast<float>(i);
      const Entity pivot = cmd.spawn();
      Transform pivot_t;
      pivot_t.rotation = glm::angleAxis(1.3f * static_cast<float>(i), glm::vec3(0, 1, 0));
      cmd.insert(pivot, pivot_t).insert(pivot, Parent{sun}).insert(pivot, Spin{2.2f / std::sqrt(orbit)});
      const Entity planet = cmd.spawn();
      cmd.insert(planet, Transform::from_translation({orbit, 0, 0}))
          .insert(planet, Parent{pivot})
          .insert(planet, Body{static_cast<std::uint8_t>(80 + 35 * i), 140, static_cast<std::uint8_t>(255 - 30 * i), 4})
          .insert(planet, Spin{3.0f});
      for (int m = 0; m < i % 3; ++m) {
        const Entity moon = cmd.spawn();
        cmd.insert(moon, Transform::from_translation({1.2f + 0.7f * static_cast<float>(m), 0, 0}))
            .insert(moon, Parent{planet})
            .insert(moon, Body{200, 200, 200, 2});
      }
    }
  }
};

int parse_int(std::string_view flag, const char* value) {
  char* end = nullptr;
  const long v = value ? std::strtol(value, &end, 10) : 0;
  if (!value || *end != '\0' || v <= 0 || v > 1000000) {
    std::cerr << "engine_demo: " << flag << " needs a positive integer (got '" << (value ? value : "") << "')\n";
    std::exit(2);
  }
  return static_cast<int>(v);
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 240, threads = 0;
  std::string out = "out/engine_demo.png";
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : nullptr;
    if (a == "--frames") frames = parse_int(a, next), ++i;
    else if (a == "--threads") threads = parse_int(a, next), ++i;
    else if (a == "--out" && next) out = next, ++i;
    else {
      std::cerr << "engine_demo: unknown argument '" << a << "' (use --frames N --threads T --out PATH)\n";
      return 2;
    }
  }
  try {
    app::AppOptions options;
    options.jobs.threads = threads;
    app::App app(options);
    auto& img = app.world().insert_resource<DemoImage>();
    img.out_path = out;
    img.frames_to_run = static_cast<std::uint64_t>(frames);
    app.add_plugin<SolarSystemPlugin>();
    app.run(static_cast<std::uint64_t>(frames));

    std::printf("engine_demo: %d frames, %zu entities, %d threads -> %s\n", frames, app.world().entity_count(),
                app.jobs().thread_count(), out.c_str());
    std::printf("%-24s %-14s %10s %12s\n", "system", "phase", "runs", "mean ms");
    for (const auto& s : app.schedule().stats())
      std::printf("%-24s %-14s %10llu %12.4f\n", s.name.c_str(), std::string(phase_name(s.phase)).c_str(),
                  static_cast<unsigned long long>(s.runs), s.runs ? s.total_ms / static_cast<double>(s.runs) : 0.0);
  } catch (const std::exception& e) {
    std::cerr << "engine_demo: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
