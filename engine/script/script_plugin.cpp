#include "engine/script/script_plugin.h"

#include "engine/core/log.h"
#include "engine/input/input_state.h"

namespace engine::script {

namespace {

// Exclusive access: a script may touch any entity or resource.
void run_scripts(ecs::World& world) {
  const double dt = world.resource<app::Time>().delta_seconds;
  world.resource<ScriptRuntime>().run_frame(world, dt);
}

}  // namespace

void ScriptPlugin::build(app::App& app) {
  ecs::World& world = app.world();
  if (!world.has_resource<core::Log>()) world.insert_resource<core::Log>();
  if (!world.has_resource<input::InputState>()) world.insert_resource<input::InputState>();
  world.insert_resource<ScriptRuntime>(settings_);
  app.add_system(schedule::Phase::Update, "script::run_scripts", run_scripts);
}

}  // namespace engine::script
