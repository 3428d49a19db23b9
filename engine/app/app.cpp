#include "engine/app/app.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <chrono>

namespace engine::app {

namespace {
void keep_freed_memory() {
#ifdef __GLIBC__
  // Blocks up to glibc's largest threshold (32 MB on 64-bit) come from the
  // heap, and the heap is not trimmed below 512 MB of free space.
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 512 * 1024 * 1024);
#endif
}
}  // namespace

App::App(AppOptions options) : options_(options), jobs_(options.jobs) {
  if (options_.keep_freed_memory) keep_freed_memory();
  world_.insert_resource<Time>();
  world_.resource<Time>().delta_seconds = options_.fixed_delta_seconds > 0 ? options_.fixed_delta_seconds : 0.0;
  world_.insert_resource<AppExit>();
}

App& App::add_plugin(std::unique_ptr<Plugin> plugin) {
  std::string name(plugin->name());
  if (plugin_names_.contains(name)) return *this;
  plugin_names_.insert(name);
  plugin->build(*this);
  plugins_.push_back(std::move(plugin));
  return *this;
}

void App::update() {
  using clock = std::chrono::steady_clock;
  const auto start = clock::now();
  if (!started_) {
    schedule_.run_phase(world_, schedule::Phase::Startup, &jobs_);
    started_ = true;
  }
  // A paused frame's systems see no time pass; the step comes back after it.
  const double step = world_.resource<Time>().delta_seconds;
  const bool paused = world_.resource<Time>().paused;
  if (paused) world_.resource<Time>().delta_seconds = 0.0;
  for (schedule::Phase p : schedule::kFramePhases) schedule_.run_phase(world_, p, &jobs_);

  auto& time = world_.resource<Time>();
  if (paused) time.delta_seconds = step;
  if (options_.fixed_delta_seconds <= 0)
    time.delta_seconds = std::chrono::duration<double>(clock::now() - start).count();
  if (!paused) time.elapsed_seconds += time.delta_seconds;
  ++time.frame;
}

int App::run(std::optional<std::uint64_t> max_frames) {
  std::uint64_t frames = 0;
  while (!world_.resource<AppExit>().requested && (!max_frames || frames < *max_frames)) {
    update();
    ++frames;
  }
  return world_.resource<AppExit>().code;
}

}  // namespace engine::app
