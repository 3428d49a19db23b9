#pragma once
// App = world + schedule + job system + frame loop.
#include <cstdint>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "engine/app/plugin.h"
#include "engine/ecs/ecs.h"
#include "engine/jobs/job_system.h"
#include "engine/schedule/schedule.h"

namespace engine::app {

// Frame clock. With a fixed step (the default) every run of the same inputs
// sees the same delta, which keeps simulations and renders repeatable.
struct Time {
  std::uint64_t frame = 0;        // frames completed before this one
  double delta_seconds = 1.0 / 60.0;
  double elapsed_seconds = 0.0;   // simulated time at the start of this frame
  // Game time stands still: systems run (rendering, the editor) but see a
  // delta of 0, and elapsed_seconds does not advance. For a photo mode, or a
  // progressive view that must not restart as the scene animates.
  bool paused = false;
};

// Any system may ask the loop to stop after the current frame.
struct AppExit {
  bool requested = false;
  int code = 0;
};

struct AppOptions {
  jobs::JobSystemOptions jobs;
  // Fixed simulated step; 0 = use measured wall-clock time per frame.
  double fixed_delta_seconds = 1.0 / 60.0;
  // Frames allocate and free the same large buffers (images, per-frame
  // arrays). glibc hands a freed block over 128 KB back to the OS at once and
  // faults it in again, zeroed, when the next frame asks: 1.4 ms of a 640x360
  // real-time TransGI frame on 2 cores (docs/performance.md). On = keep freed
  // memory in the process for the next frame (glibc's mmap and trim
  // thresholds, process-wide), at the cost of a resident size that does not
  // shrink after a peak.
  bool keep_freed_memory = true;
};

class App {
 public:
  explicit App(AppOptions options = {});

  [[nodiscard]] ecs::World& world() { return world_; }
  [[nodiscard]] schedule::Schedule& schedule() { return schedule_; }
  [[nodiscard]] jobs::JobSystem& jobs() { return jobs_; }

  App& add_plugin(std::unique_ptr<Plugin> plugin);
  template <class P, class... Args>
  App& add_plugin(Args&&... args) {
    return add_plugin(std::make_unique<P>(std::forward<Args>(args)...));
  }
  [[nodiscard]] bool has_plugin(std::string_view name) const { return plugin_names_.contains(std::string(name)); }

  template <class Fn>
  App& add_system(schedule::Phase phase, std::string name, Fn fn) {
    schedule_.add_system(phase, std::move(name), std::move(fn));
    return *this;
  }

  // One frame: Startup (first frame only), then Update..Present.
  void update();
  // Runs frames until a system requests exit or max_frames have run.
  // Returns AppExit::code.
  int run(std::optional<std::uint64_t> max_frames = std::nullopt);

 private:
  AppOptions options_;
  jobs::JobSystem jobs_;
  ecs::World world_;
  schedule::Schedule schedule_;
  std::vector<std::unique_ptr<Plugin>> plugins_;
  std::set<std::string, std::less<>> plugin_names_;
  bool started_ = false;
};

}  // namespace engine::app
