#pragma once
// A Lua gameplay script on an entity. The file runs once per entity, in its
// own _ENV, and may define the hooks init(self), update(self, dt),
// on_message(self, id, msg), on_reload(self) and final(self). `self` is a
// per-entity table; self.entity is this entity's handle.
#include <map>
#include <string>
#include <variant>

namespace engine::script {

// A value a script declares with property("name", default) and an editor
// may change: a number, a boolean or a string.
using PropertyValue = std::variant<double, bool, std::string>;

struct Script {
  std::string path;  // the .lua file; relative paths are under ScriptSettings::root
  // Values set from outside the script (level file, inspector); they win
  // over the defaults the script declares.
  std::map<std::string, PropertyValue> overrides;
};

}  // namespace engine::script
