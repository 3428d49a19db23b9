#pragma once
// What the Lua API functions reach while scripts run (private to engine/script).
#include <deque>
#include <map>
#include <string>
#include <vector>

#include "engine/ecs/world.h"
#include "engine/script/script_runtime.h"

struct lua_State;

namespace engine::script::detail {

struct Message {
  ecs::Entity target, sender;
  std::string id;
  int payload_ref = 0;  // registry reference to the message table (or nil)
};

struct ScriptContext {
  ecs::World* world = nullptr;  // set only while the runtime runs scripts
  double dt = 0.0;
  std::deque<Message> messages;
  std::vector<CloneHook> clone_hooks;
  ecs::Entity current;  // whose script runs now (the sender of send())
  // Set only while a script file runs, for property().
  int loading_self_ref = 0;
  std::vector<ScriptProperty>* loading_properties = nullptr;
  const std::map<std::string, PropertyValue>* loading_overrides = nullptr;

  void log(int level, const std::string& source, const std::string& text) const;
};

ScriptContext& context_of(lua_State* L);
void set_context(lua_State* L, ScriptContext* context);

// Adds scene, input, time, log, send, property and print to the table on top
// of the stack (the sandbox's globals).
void register_api(lua_State* L);
// Pushes a handle (userdata) for e.
void push_entity(lua_State* L, ecs::Entity e);
// Pushes a property value as a Lua value; reads one back (false if the Lua
// value is not a number, boolean or string).
void push_property(lua_State* L, const PropertyValue& v);
bool to_property(lua_State* L, int index, PropertyValue& out);

}  // namespace engine::script::detail
