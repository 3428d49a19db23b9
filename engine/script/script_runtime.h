#pragma once
// Runs the Script components of a world. One Lua state serves every script;
// each script instance has its own environment and `self` table.
//
// One frame (run_frame), in this order:
//  1. scripts whose entity died or lost its Script get final(self);
//  2. new Script components are loaded: the file runs once in its own _ENV
//     (declaring its properties), then init(self);
//  3. files changed on disk are reloaded, keeping `self`, then on_reload(self);
//  4. update(self, dt) for every enabled script, in entity order;
//  5. messages sent with send() are delivered to on_message(self, id, msg).
// A hook that errors disables only its own script and logs the message with
// its traceback, and the script's state (self, its globals) is freed;
// editing the file starts it afresh. An edit that does not compile stops the
// script but keeps its state for the fixed file. Each script's allocations
// are charged to it (LuaSandbox owners): one that leaks stops at its own
// budget, at its own line, and its memory goes back to the others.
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "engine/ecs/world.h"
#include "engine/script/lua_sandbox.h"
#include "engine/script/script_component.h"

namespace engine::script {

struct ScriptSettings {
  std::filesystem::path root = ".";  // relative Script::path values are under it
  SandboxLimits limits;
  // On = a script file changed on disk is reloaded at the next frame, at the
  // cost of one stat() per distinct file per frame.
  bool hot_reload = true;
  // Higher = longer message chains delivered in one frame, at the cost of a
  // runaway ping-pong taking longer per frame (the rest waits a frame).
  int max_messages_per_frame = 1024;
};

struct ScriptProperty {
  std::string name;
  PropertyValue value;  // the script's current self[name]
};

// Copies a plugin's own components from a prefab entity to its clone, for
// scene.spawn("prefab name").
using CloneHook = std::function<void(ecs::World&, ecs::Entity prefab, ecs::Entity clone)>;

class ScriptRuntime {
 public:
  explicit ScriptRuntime(ScriptSettings settings = {});
  ~ScriptRuntime();
  ScriptRuntime(const ScriptRuntime&) = delete;
  ScriptRuntime& operator=(const ScriptRuntime&) = delete;

  void run_frame(ecs::World& world, double dt);
  // final(self) for every script, then forgets them (the app is closing).
  void shutdown(ecs::World& world);

  [[nodiscard]] std::size_t instance_count() const;
  [[nodiscard]] bool is_enabled(ecs::Entity e) const;
  // The properties the entity's script declared, in declaration order.
  [[nodiscard]] std::vector<ScriptProperty> properties(ecs::Entity e) const;
  // Sets self[name] and the Script component's override (so a reload keeps
  // it). False if the entity has no running script or no such property.
  bool set_property(ecs::World& world, ecs::Entity e, const std::string& name, const PropertyValue& value);

  void add_clone_hook(CloneHook hook);
  [[nodiscard]] const ScriptSettings& settings() const;
  [[nodiscard]] const LuaSandbox& sandbox() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace engine::script
