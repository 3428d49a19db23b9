// Lua gameplay scripts from untrusted text: the script runs in the sandbox
// with its hooks (init, update, on_message, final) over three frames, with a
// small instruction budget and memory cap. Errors disable the script and are
// logged; nothing may crash, leak or escape the sandbox.
#include <string>

#include "engine/app/app.h"
#include "engine/core/log.h"
#include "engine/scene/components.h"
#include "engine/script/script_plugin.h"
#include "engine/transform/transform_plugin.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > (1u << 16)) return 0;
  transgi_fuzz::write_input("fuzzed.lua", data, size);
  engine::app::App app(engine::app::AppOptions{.jobs = {.threads = 1}});
  engine::script::ScriptSettings s;
  s.root = transgi_fuzz::input_folder();
  s.limits.instruction_budget = 100'000;
  s.limits.memory_bytes = std::size_t{16} << 20;
  s.hot_reload = false;
  app.add_plugin<engine::transform::TransformPlugin>();
  app.add_plugin<engine::script::ScriptPlugin>(s);
  auto& world = app.world();
  world.resource<engine::core::Log>().set_echo(false);
  for (int i = 0; i < 2; ++i) {
    const engine::ecs::Entity e = world.spawn();
    world.emplace<engine::transform::Transform>(e);
    world.emplace<engine::scene::Name>(e, engine::scene::Name{i == 0 ? "player" : "crate"});
    world.emplace<engine::script::Script>(e, engine::script::Script{"fuzzed.lua", {}});
  }
  for (int frame = 0; frame < 3; ++frame) app.jobs().run([&] { app.update(); });
  return 0;
}
