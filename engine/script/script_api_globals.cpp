// The global API tables a script sees:
//   scene.find(name) -> entity | nil         scene.spawn(prefab or mesh name [, {x,y,z}]) -> entity
//   scene.despawn(e) -> bool                 scene.raycast(origin, dir [, max_distance]) -> {entity, distance, position} | nil
//   input.down(key) / input.pressed(key) / input.released(key) -> bool;  input.mouse() -> x, y
//   time.now() -> seconds, time.dt() -> seconds, time.frame() -> integer
//   log.info(...) / log.warn(...) / log.error(...); print(...) is log.info
//   sky.set_yaw(radians) / sky.get_yaw() / sky.set_strength(s) / sky.get_strength()  (the environment map)
//   send(entity, id, msg)                    property(name, default) -> value
#include <string>
#include <vector>

#include <lua.hpp>

#include "engine/app/app.h"
#include "engine/core/log.h"
#include "engine/input/input_state.h"
#include "engine/rt/rt_scene.h"
#include "engine/scene/components.h"
#include "engine/scene/sun.h"
#include "engine/scene/find_named.h"
#include "engine/scene/scene_assets.h"
#include "engine/script/script_api.h"
#include "engine/script/script_context.h"
#include "engine/transform/transform.h"

namespace engine::script::detail {

namespace {

char kContextKey;

ecs::World& world_of(lua_State* L) { return *context_of(L).world; }

// --- scene -------------------------------------------------------------------

int scene_find(lua_State* L) {
  const ecs::Entity e = scene::find_named(world_of(L), luaL_checkstring(L, 1));
  if (e.is_null()) lua_pushnil(L);
  else push_entity(L, e);
  return 1;
}

int scene_spawn(lua_State* L) {
  ecs::World& world = world_of(L);
  const std::string name = luaL_checkstring(L, 1);
  const bool placed = !lua_isnoneornil(L, 2);
  const glm::vec3 at = placed ? check_vec3(L, 2, "spawn position") : glm::vec3(0.0f);
  const ecs::Entity prefab = scene::find_named(world, name);
  ecs::Entity e;
  if (!prefab.is_null()) {
    e = world.spawn();
    transform::Transform t;
    if (const auto* pt = world.try_get<transform::Transform>(prefab)) t = *pt;
    if (placed) t.translation = at;
    world.emplace<transform::Transform>(e, t);
    if (const auto* m = world.try_get<scene::MeshInstance>(prefab)) world.emplace<scene::MeshInstance>(e, *m);
    if (const auto* l = world.try_get<scene::PunctualLight>(prefab)) world.emplace<scene::PunctualLight>(e, *l);
    if (const auto* p = world.try_get<transform::Parent>(prefab)) world.emplace<transform::Parent>(e, *p);
    for (const CloneHook& hook : context_of(L).clone_hooks) hook(world, prefab, e);
  } else {
    const auto* assets = world.try_resource<scene::SceneAssets>();
    std::uint32_t mesh = UINT32_MAX;
    for (std::size_t i = 0; assets && i < assets->meshes.size(); ++i)
      if (assets->meshes[i]->name == name) mesh = static_cast<std::uint32_t>(i);
    if (mesh == UINT32_MAX) luaL_error(L, "scene.spawn: no entity (prefab) or mesh named '%s'", name.c_str());
    e = world.spawn();
    world.emplace<transform::Transform>(e, transform::Transform::from_translation(at));
    world.emplace<scene::MeshInstance>(e, scene::MeshInstance{mesh});
  }
  world.emplace<scene::Name>(e, scene::Name{name + "#" + std::to_string(e.index)});
  push_entity(L, e);
  return 1;
}

void despawn_tree(ecs::World& world, ecs::Entity e) {
  std::vector<ecs::Entity> children;
  world.view<const transform::Parent>().each([&](ecs::Entity c, const transform::Parent& p) {
    if (p.entity == e) children.push_back(c);
  });
  for (ecs::Entity c : children) despawn_tree(world, c);
  world.despawn(e);
}

int scene_despawn(lua_State* L) {
  const ecs::Entity e = check_entity(L, 1);
  ecs::World& world = world_of(L);
  const bool was_alive = world.alive(e);
  if (was_alive) despawn_tree(world, e);
  lua_pushboolean(L, was_alive);
  return 1;
}

int scene_raycast(lua_State* L) {
  const glm::vec3 origin = check_vec3(L, 1, "raycast origin");
  const glm::vec3 dir = check_vec3(L, 2, "raycast direction");
  const float max_distance = lua_isnoneornil(L, 3) ? INFINITY : check_finite(L, 3, "max_distance");
  const float len = glm::length(dir);
  if (!(len > 1e-12f)) luaL_error(L, "scene.raycast: the direction has zero length");
  const auto* rt = world_of(L).try_resource<rt::RtScene>();
  if (!rt) luaL_error(L, "scene.raycast: this app has no ray-tracing scene");
  rt::Ray ray;
  ray.origin = origin;
  ray.direction = dir / len;
  ray.tmax = max_distance;
  rt::Hit hit;
  if (!rt->intersect(ray, hit) || !world_of(L).alive(hit.entity)) {
    lua_pushnil(L);
    return 1;
  }
  const glm::vec3 p = ray.origin + hit.t * ray.direction;
  lua_createtable(L, 0, 3);
  push_entity(L, hit.entity);
  lua_setfield(L, -2, "entity");
  lua_pushnumber(L, hit.t);
  lua_setfield(L, -2, "distance");
  lua_createtable(L, 0, 3);
  lua_pushnumber(L, p.x);
  lua_setfield(L, -2, "x");
  lua_pushnumber(L, p.y);
  lua_setfield(L, -2, "y");
  lua_pushnumber(L, p.z);
  lua_setfield(L, -2, "z");
  lua_setfield(L, -2, "position");
  return 1;
}

// --- input, time -------------------------------------------------------------

const input::InputState* input_of(lua_State* L) { return world_of(L).try_resource<input::InputState>(); }

int input_down(lua_State* L) {
  const auto* in = input_of(L);
  lua_pushboolean(L, in && in->is_down(luaL_checkstring(L, 1)));
  return 1;
}
int input_pressed(lua_State* L) {
  const auto* in = input_of(L);
  lua_pushboolean(L, in && in->was_pressed(luaL_checkstring(L, 1)));
  return 1;
}
int input_released(lua_State* L) {
  const auto* in = input_of(L);
  lua_pushboolean(L, in && in->released.contains(luaL_checkstring(L, 1)));
  return 1;
}
int input_mouse(lua_State* L) {
  const auto* in = input_of(L);
  lua_pushnumber(L, in ? in->mouse.x : 0.0);
  lua_pushnumber(L, in ? in->mouse.y : 0.0);
  return 2;
}

int time_now(lua_State* L) {
  const auto* t = world_of(L).try_resource<app::Time>();
  lua_pushnumber(L, t ? t->elapsed_seconds : 0.0);
  return 1;
}
int time_dt(lua_State* L) {
  lua_pushnumber(L, context_of(L).dt);
  return 1;
}
int time_frame(lua_State* L) {
  const auto* t = world_of(L).try_resource<app::Time>();
  lua_pushinteger(L, t ? static_cast<lua_Integer>(t->frame) : 0);
  return 1;
}

// --- sky ---------------------------------------------------------------------

scene::Environment& environment_of(lua_State* L, scene::SceneAssets** assets_out = nullptr) {
  auto* assets = world_of(L).try_resource<scene::SceneAssets>();
  if (!assets || !assets->environment) luaL_error(L, "sky: this scene has no environment map");
  if (assets_out) *assets_out = assets;
  return *assets->environment;
}
int sky_set_yaw(lua_State* L) {
  const float yaw = check_finite(L, 1, "yaw");
  scene::SceneAssets* assets = nullptr;
  scene::Environment& env = environment_of(L, &assets);
  if (env.yaw() != yaw) {
    env.set_yaw(yaw);
    ++assets->edit_version;
  }
  return 0;
}
int sky_get_yaw(lua_State* L) {
  lua_pushnumber(L, environment_of(L).yaw());
  return 1;
}
int sky_set_strength(lua_State* L) {
  const float s = check_finite(L, 1, "strength");
  if (s < 0) luaL_error(L, "sky.set_strength: strength must be >= 0");
  scene::SceneAssets* assets = nullptr;
  scene::Environment& env = environment_of(L, &assets);
  if (env.strength() != s) {
    env.set_strength(s);
    ++assets->edit_version;
  }
  return 0;
}
int sky_get_strength(lua_State* L) {
  lua_pushnumber(L, environment_of(L).strength());
  return 1;
}

// --- sun: the first directional light, by elevation and azimuth (degrees) --

int sun_set(lua_State* L) {
  const float elevation = check_finite(L, 1, "elevation"), azimuth = check_finite(L, 2, "azimuth");
  if (elevation < -90.0f || elevation > 90.0f) luaL_error(L, "sun.set: elevation must lie in [-90, 90] degrees");
  if (!scene::find_sun(world_of(L))) luaL_error(L, "sun.set: this scene has no directional light");
  scene::set_sun(world_of(L), elevation, azimuth);
  return 0;
}
int sun_get(lua_State* L) {
  ecs::World& world = world_of(L);
  const auto sun = scene::find_sun(world);
  if (!sun) luaL_error(L, "sun.get: this scene has no directional light");
  const glm::vec2 a = scene::sun_angles(glm::normalize(world.get<transform::Transform>(*sun).rotation * glm::vec3(0, 0, 1)));
  lua_pushnumber(L, a.x);
  lua_pushnumber(L, a.y);
  return 2;
}

// --- log, send, property -----------------------------------------------------

std::string joined_arguments(lua_State* L) {
  std::string text;
  for (int i = 1; i <= lua_gettop(L); ++i) {
    if (i > 1) text += ' ';
    std::size_t n = 0;
    const char* s = luaL_tolstring(L, i, &n);
    text.append(s, n);
    lua_pop(L, 1);
  }
  return text;
}

std::string where(lua_State* L) {
  lua_Debug ar;
  if (lua_getstack(L, 1, &ar) && lua_getinfo(L, "Sl", &ar) && ar.currentline > 0)
    return std::string(ar.short_src) + ":" + std::to_string(ar.currentline);
  return "script";
}

template <int Level>
int log_at(lua_State* L) {
  context_of(L).log(Level, where(L), joined_arguments(L));
  return 0;
}

int send(lua_State* L) {
  const ecs::Entity target = check_entity(L, 1);
  const std::string id = luaL_checkstring(L, 2);
  if (!lua_isnoneornil(L, 3)) luaL_checktype(L, 3, LUA_TTABLE);
  lua_settop(L, 3);
  ScriptContext& ctx = context_of(L);
  ctx.messages.push_back({target, ctx.current, id, luaL_ref(L, LUA_REGISTRYINDEX)});
  return 0;
}

int property(lua_State* L) {
  ScriptContext& ctx = context_of(L);
  if (!ctx.loading_properties) luaL_error(L, "property() may only be called while the script file loads, not from a hook");
  const std::string name = luaL_checkstring(L, 1);
  PropertyValue value;
  if (!to_property(L, 2, value)) luaL_error(L, "property('%s'): the default must be a number, boolean or string", name.c_str());
  if (name == "entity") luaL_error(L, "property('entity'): the name is taken by self.entity");
  for (const ScriptProperty& p : *ctx.loading_properties)
    if (p.name == name) luaL_error(L, "property('%s') is declared twice", name.c_str());
  if (auto it = ctx.loading_overrides->find(name); it != ctx.loading_overrides->end() && it->second.index() == value.index())
    value = it->second;
  lua_rawgeti(L, LUA_REGISTRYINDEX, ctx.loading_self_ref);  // self
  if (lua_getfield(L, -1, name.c_str()) != LUA_TNIL) to_property(L, -1, value);  // a reload keeps the live value
  lua_pop(L, 1);
  push_property(L, value);
  lua_setfield(L, -2, name.c_str());
  lua_pop(L, 1);
  ctx.loading_properties->push_back({name, value});
  push_property(L, value);
  return 1;
}

void set_table(lua_State* L, const char* name, const luaL_Reg* fns) {
  lua_newtable(L);
  luaL_setfuncs(L, fns, 0);
  lua_setfield(L, -2, name);
}

}  // namespace

ScriptContext& context_of(lua_State* L) {
  lua_rawgetp(L, LUA_REGISTRYINDEX, &kContextKey);
  auto* ctx = static_cast<ScriptContext*>(lua_touserdata(L, -1));
  lua_pop(L, 1);
  if (!ctx || !ctx->world) luaL_error(L, "the engine API is only available while the script runtime runs");
  return *ctx;
}

void set_context(lua_State* L, ScriptContext* context) {
  lua_pushlightuserdata(L, context);
  lua_rawsetp(L, LUA_REGISTRYINDEX, &kContextKey);
}

void push_property(lua_State* L, const PropertyValue& v) {
  if (const double* d = std::get_if<double>(&v)) lua_pushnumber(L, *d);
  else if (const bool* b = std::get_if<bool>(&v)) lua_pushboolean(L, *b);
  else {
    const std::string& s = std::get<std::string>(v);
    lua_pushlstring(L, s.data(), s.size());
  }
}

bool to_property(lua_State* L, int index, PropertyValue& out) {
  switch (lua_type(L, index)) {
    case LUA_TNUMBER: out = static_cast<double>(lua_tonumber(L, index)); return true;
    case LUA_TBOOLEAN: out = lua_toboolean(L, index) != 0; return true;
    case LUA_TSTRING: out = std::string(lua_tostring(L, index)); return true;
    default: return false;
  }
}

void register_api(lua_State* L) {
  register_entity_types(L);
  const luaL_Reg scene_fns[] = {{"find", scene_find}, {"spawn", scene_spawn}, {"despawn", scene_despawn},
                                {"raycast", scene_raycast}, {nullptr, nullptr}};
  const luaL_Reg input_fns[] = {{"down", input_down}, {"pressed", input_pressed}, {"released", input_released},
                                {"mouse", input_mouse}, {nullptr, nullptr}};
  const luaL_Reg time_fns[] = {{"now", time_now}, {"dt", time_dt}, {"frame", time_frame}, {nullptr, nullptr}};
  const luaL_Reg log_fns[] = {{"info", log_at<0>}, {"warn", log_at<1>}, {"error", log_at<2>}, {nullptr, nullptr}};
  set_table(L, "scene", scene_fns);
  set_table(L, "input", input_fns);
  set_table(L, "time", time_fns);
  set_table(L, "log", log_fns);
  const luaL_Reg sky_fns[] = {{"set_yaw", sky_set_yaw}, {"get_yaw", sky_get_yaw}, {"set_strength", sky_set_strength},
                              {"get_strength", sky_get_strength}, {nullptr, nullptr}};
  set_table(L, "sky", sky_fns);
  const luaL_Reg sun_fns[] = {{"set", sun_set}, {"get", sun_get}, {nullptr, nullptr}};
  set_table(L, "sun", sun_fns);
  lua_pushcfunction(L, log_at<0>);
  lua_setfield(L, -2, "print");
  lua_pushcfunction(L, send);
  lua_setfield(L, -2, "send");
  lua_pushcfunction(L, property);
  lua_setfield(L, -2, "property");
}

}  // namespace engine::script::detail
