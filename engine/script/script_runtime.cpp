#include "engine/script/script_runtime.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <system_error>

#include <lua.hpp>

#include "engine/core/log.h"
#include "engine/script/script_context.h"

namespace engine::script {

namespace fs = std::filesystem;

namespace {

struct Instance {
  std::string path;  // Script::path as the component gave it
  fs::path file;     // resolved against ScriptSettings::root
  int env_ref = LUA_NOREF, self_ref = LUA_NOREF;
  std::uint32_t owner = 0;  // LuaSandbox owner: what this script allocated is charged to it
  bool enabled = false;
  std::vector<ScriptProperty> properties;
  fs::file_time_type mtime{};
};

fs::file_time_type mtime_of(const fs::path& p) {
  std::error_code ec;
  const auto t = fs::last_write_time(p, ec);
  return ec ? fs::file_time_type::min() : t;
}

}  // namespace

void detail::ScriptContext::log(int level, const std::string& source, const std::string& text) const {
  const auto l = static_cast<core::LogLevel>(std::clamp(level, 0, 2));
  if (world)
    if (auto* log = world->try_resource<core::Log>()) {
      log->add(l, source, text);
      return;
    }
  std::fprintf(stderr, "[%s] %s: %s\n", core::log_level_name(l), source.c_str(), text.c_str());
}

struct ScriptRuntime::Impl {
  ScriptSettings settings;
  LuaSandbox sandbox;
  detail::ScriptContext ctx;
  std::map<ecs::Entity, Instance> instances;  // ordered: hooks run in entity order

  explicit Impl(ScriptSettings s) : settings(std::move(s)), sandbox(settings.limits) {
    lua_State* L = sandbox.state();
    detail::set_context(L, &ctx);
    sandbox.push_globals();
    detail::register_api(L);
    lua_pop(L, 1);
  }
  ~Impl() {
    lua_State* L = sandbox.state();
    for (auto& [e, inst] : instances) release(inst);
    for (detail::Message& m : ctx.messages) luaL_unref(L, LUA_REGISTRYINDEX, m.payload_ref);
  }

  [[nodiscard]] lua_State* L() const { return sandbox.state(); }

  void release(Instance& inst) const {
    luaL_unref(L(), LUA_REGISTRYINDEX, inst.env_ref);
    luaL_unref(L(), LUA_REGISTRYINDEX, inst.self_ref);
    inst.env_ref = inst.self_ref = LUA_NOREF;
  }

  void error(const Instance& inst, ecs::Entity e, const std::string& what, const std::string& message) const {
    const auto mb = [](std::size_t bytes) { return std::to_string(static_cast<double>(bytes) / (1 << 20)).substr(0, 5); };
    ctx.log(2, "script " + inst.path,
            what + " failed on entity " + std::to_string(e.index) + " (" + inst.file.string() + "; it held " +
                mb(sandbox.memory_used(inst.owner)) + " MB of its " + mb(settings.limits.owner_memory_bytes) +
                " MB); the script is disabled until its file changes:\n" + message);
  }

  // A script whose hook failed is disabled and its tables dropped and
  // collected: what it held is freed for the others (a leak does not outlive
  // its script). Its file, once changed, starts it afresh (a new self, then
  // init). A reload that does not compile only stops it (reload_changed).
  void disable(Instance& inst) {
    inst.enabled = false;
    release(inst);
    sandbox.collect();
  }

  // Runs the file in a fresh _ENV (declaring properties into self). False on error.
  bool run_file(ecs::Entity e, Instance& inst, const std::map<std::string, PropertyValue>& overrides) {
    std::ifstream in(inst.file, std::ios::binary);
    if (!in) {
      error(inst, e, "loading", "cannot open '" + inst.file.string() + "'");
      return false;
    }
    std::ostringstream text;
    text << in.rdbuf();
    lua_State* L = this->L();
    LuaSandbox::OwnerScope scope(sandbox, inst.owner);
    sandbox.push_new_env();
    if (std::string message = sandbox.load(text.str(), inst.path, -1); !message.empty()) {
      lua_pop(L, 1);
      error(inst, e, "compiling", message);
      return false;
    }
    std::vector<ScriptProperty> declared;
    ctx.current = e;
    ctx.loading_self_ref = inst.self_ref;
    ctx.loading_properties = &declared;
    ctx.loading_overrides = &overrides;
    const std::string message = sandbox.call(0, 0);
    ctx.loading_properties = nullptr;
    ctx.loading_overrides = nullptr;
    if (!message.empty()) {
      lua_pop(L, 1);  // the env
      error(inst, e, "running the file", message);
      return false;
    }
    luaL_unref(L, LUA_REGISTRYINDEX, inst.env_ref);
    inst.env_ref = luaL_ref(L, LUA_REGISTRYINDEX);  // pops the env
    inst.properties = std::move(declared);
    return true;
  }

  // Calls hook `name` with (self, args pushed by push_args); no-op if the
  // script does not define it. Disables the script on error.
  template <class PushArgs>
  void call_hook(ecs::Entity e, Instance& inst, const char* name, PushArgs&& push_args) {
    if (!inst.enabled) return;
    lua_State* L = this->L();
    LuaSandbox::OwnerScope scope(sandbox, inst.owner);
    lua_rawgeti(L, LUA_REGISTRYINDEX, inst.env_ref);
    if (lua_getfield(L, -1, name) != LUA_TFUNCTION) {
      lua_pop(L, 2);
      return;
    }
    lua_remove(L, -2);
    lua_rawgeti(L, LUA_REGISTRYINDEX, inst.self_ref);
    const int extra = push_args(L);
    ctx.current = e;
    if (std::string message = sandbox.call(1 + extra, 0); !message.empty()) {
      error(inst, e, std::string(name) + "()", message);
      disable(inst);
    }
  }
  void call_hook(ecs::Entity e, Instance& inst, const char* name) {
    call_hook(e, inst, name, [](lua_State*) { return 0; });
  }

  // A fresh self table for the instance, charged to its owner.
  void make_self(ecs::Entity e, Instance& inst) {
    lua_State* L = this->L();
    LuaSandbox::OwnerScope scope(sandbox, inst.owner);
    lua_createtable(L, 0, 4);
    detail::push_entity(L, e);
    lua_setfield(L, -2, "entity");
    inst.self_ref = luaL_ref(L, LUA_REGISTRYINDEX);
  }

  void start(ecs::Entity e, const Script& script) {
    Instance inst;
    inst.path = script.path;
    inst.file = fs::path(script.path).is_absolute() ? fs::path(script.path) : settings.root / script.path;
    inst.mtime = mtime_of(inst.file);
    inst.owner = sandbox.add_owner();
    make_self(e, inst);
    inst.enabled = run_file(e, inst, script.overrides);
    Instance& placed = instances.emplace(e, std::move(inst)).first->second;
    if (!placed.enabled) {
      disable(placed);
      return;
    }
    call_hook(e, placed, "init");
  }

  void stop(ecs::Entity e) {
    auto it = instances.find(e);
    if (it == instances.end()) return;
    call_hook(e, it->second, "final");
    release(it->second);
    instances.erase(it);
  }

  void reload_changed(ecs::World& world) {
    std::map<fs::path, fs::file_time_type> now;
    for (auto& [e, inst] : instances) {
      auto [it, fresh] = now.try_emplace(inst.file);
      if (fresh) it->second = mtime_of(inst.file);
      if (it->second == inst.mtime) continue;
      inst.mtime = it->second;
      const auto* script = world.try_get<Script>(e);
      static const std::map<std::string, PropertyValue> kNone;
      // A disabled script's state was freed: it starts afresh.
      const bool restart = inst.self_ref == LUA_NOREF;
      if (restart) make_self(e, inst);
      if (!run_file(e, inst, script ? script->overrides : kNone)) {
        // The new file is broken: the script stops, but keeps its state for
        // the fixed file (a typo while editing loses nothing).
        inst.enabled = false;
        continue;
      }
      inst.enabled = true;
      ctx.log(0, "script " + inst.path, (restart ? "restarted on entity " : "reloaded on entity ") + std::to_string(e.index));
      call_hook(e, inst, restart ? "init" : "on_reload");
    }
  }

  void deliver_messages() {
    lua_State* L = this->L();
    for (int n = 0; n < settings.max_messages_per_frame && !ctx.messages.empty(); ++n) {
      detail::Message m = std::move(ctx.messages.front());
      ctx.messages.pop_front();
      auto it = instances.find(m.target);
      if (it == instances.end()) {
        ctx.log(1, "script", "message '" + m.id + "' to entity " + std::to_string(m.target.index) +
                                 ", which runs no script, was dropped");
      } else {
        call_hook(m.target, it->second, "on_message", [&](lua_State* S) {
          lua_pushlstring(S, m.id.data(), m.id.size());
          lua_rawgeti(S, LUA_REGISTRYINDEX, m.payload_ref);
          return 2;
        });
      }
      luaL_unref(L, LUA_REGISTRYINDEX, m.payload_ref);
    }
  }
};

ScriptRuntime::ScriptRuntime(ScriptSettings settings) : impl_(std::make_unique<Impl>(std::move(settings))) {}
ScriptRuntime::~ScriptRuntime() = default;

void ScriptRuntime::run_frame(ecs::World& world, double dt) {
  Impl& m = *impl_;
  m.ctx.world = &world;
  m.ctx.dt = dt;
  // 1. Stop scripts whose entity or component went away (or changed file).
  std::vector<ecs::Entity> gone;
  for (const auto& [e, inst] : m.instances) {
    const Script* s = world.alive(e) ? world.try_get<Script>(e) : nullptr;
    if (!s || s->path != inst.path) gone.push_back(e);
  }
  for (ecs::Entity e : gone) m.stop(e);
  // 2. Start new ones, in entity order.
  std::vector<ecs::Entity> fresh;
  world.view<const Script>().each([&](ecs::Entity e, const Script&) {
    if (!m.instances.contains(e)) fresh.push_back(e);
  });
  std::sort(fresh.begin(), fresh.end());
  for (ecs::Entity e : fresh)
    if (world.alive(e))
      if (const Script* s = world.try_get<Script>(e)) m.start(e, *s);
  // 3. Hot reload.
  if (m.settings.hot_reload) m.reload_changed(world);
  // 4. update(self, dt); a hook may despawn entities or add scripts.
  std::vector<ecs::Entity> order;
  for (const auto& [e, inst] : m.instances) order.push_back(e);
  for (ecs::Entity e : order) {
    auto it = m.instances.find(e);
    if (it == m.instances.end() || !world.alive(e)) continue;
    m.call_hook(e, it->second, "update", [dt](lua_State* L) {
      lua_pushnumber(L, dt);
      return 1;
    });
  }
  // 5. Messages.
  m.deliver_messages();
  m.ctx.world = nullptr;
}

void ScriptRuntime::shutdown(ecs::World& world) {
  Impl& m = *impl_;
  m.ctx.world = &world;
  std::vector<ecs::Entity> all;
  for (const auto& [e, inst] : m.instances) all.push_back(e);
  for (ecs::Entity e : all) m.stop(e);
  m.ctx.world = nullptr;
}

std::size_t ScriptRuntime::instance_count() const { return impl_->instances.size(); }

bool ScriptRuntime::is_enabled(ecs::Entity e) const {
  auto it = impl_->instances.find(e);
  return it != impl_->instances.end() && it->second.enabled;
}

std::vector<ScriptProperty> ScriptRuntime::properties(ecs::Entity e) const {
  auto it = impl_->instances.find(e);
  if (it == impl_->instances.end()) return {};
  std::vector<ScriptProperty> out = it->second.properties;
  if (it->second.self_ref == LUA_NOREF) return out;  // disabled, its state freed: the values it last declared
  lua_State* L = impl_->L();
  lua_rawgeti(L, LUA_REGISTRYINDEX, it->second.self_ref);
  for (ScriptProperty& p : out) {
    lua_getfield(L, -1, p.name.c_str());
    PropertyValue v;
    if (detail::to_property(L, -1, v)) p.value = v;
    lua_pop(L, 1);
  }
  lua_pop(L, 1);
  return out;
}

bool ScriptRuntime::set_property(ecs::World& world, ecs::Entity e, const std::string& name, const PropertyValue& value) {
  auto it = impl_->instances.find(e);
  if (it == impl_->instances.end()) return false;
  auto p = std::find_if(it->second.properties.begin(), it->second.properties.end(),
                        [&](const ScriptProperty& q) { return q.name == name; });
  if (p == it->second.properties.end() || p->value.index() != value.index() || it->second.self_ref == LUA_NOREF) return false;
  lua_State* L = impl_->L();
  lua_rawgeti(L, LUA_REGISTRYINDEX, it->second.self_ref);
  detail::push_property(L, value);
  lua_setfield(L, -2, name.c_str());
  lua_pop(L, 1);
  p->value = value;
  if (auto* s = world.try_get_mut<Script>(e)) s->overrides[name] = value;
  return true;
}

void ScriptRuntime::add_clone_hook(CloneHook hook) { impl_->ctx.clone_hooks.push_back(std::move(hook)); }
const ScriptSettings& ScriptRuntime::settings() const { return impl_->settings; }
const LuaSandbox& ScriptRuntime::sandbox() const { return impl_->sandbox; }

}  // namespace engine::script
