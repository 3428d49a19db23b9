// Entity handles for Lua: a userdata holding (index, generation), never a
// component pointer. Every use checks that the entity is still alive, so a
// handle to a despawned entity gives a Lua error, not a dangling pointer.
//
//   e.transform:get_position() / :set_position(x, y, z) / :translate(dx, dy, dz)
//   e.transform:rotate(axis, radians) / :rotate(euler) / :get_rotation() / :set_rotation(euler)
//   e.transform:get_scale() / :set_scale(s) / :get_world_position() / :get_forward()
//   e.light:set_intensity(x) / :get_intensity() / :set_color(r, g, b) / :set_enabled(b) / :is_enabled() / :set_range(r)
//   e.name, e:alive(), tostring(e), e1 == e2
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/gtc/quaternion.hpp>
#include <lua.hpp>

#include "engine/scene/components.h"
#include "engine/script/script_api.h"
#include "engine/script/script_context.h"
#include "engine/transform/transform.h"

namespace engine::script::detail {

namespace {

constexpr const char* kEntityMeta = "engine.Entity";
constexpr const char* kTransformMeta = "engine.Transform";
constexpr const char* kLightMeta = "engine.Light";

ecs::Entity handle_at(lua_State* L, int index, const char* meta) {
  const auto* e = static_cast<const ecs::Entity*>(luaL_checkudata(L, index, meta));
  return *e;
}

// The live entity behind argument `index`, or a Lua error naming it.
ecs::Entity live(lua_State* L, int index, const char* meta) {
  const ecs::Entity e = handle_at(L, index, meta);
  if (!context_of(L).world->alive(e))
    luaL_error(L, "entity %d (generation %d) was despawned; its handle is stale", static_cast<int>(e.index),
               static_cast<int>(e.generation));
  return e;
}

transform::Transform& transform_of(lua_State* L) {
  const ecs::Entity e = live(L, 1, kTransformMeta);
  auto* t = context_of(L).world->try_get_mut<transform::Transform>(e);
  if (!t) luaL_error(L, "entity %d has no Transform", static_cast<int>(e.index));
  return *t;
}

scene::PunctualLight& light_of(lua_State* L) {
  const ecs::Entity e = live(L, 1, kLightMeta);
  auto* l = context_of(L).world->try_get_mut<scene::PunctualLight>(e);
  if (!l) luaL_error(L, "entity %d has no light", static_cast<int>(e.index));
  return *l;
}

void push_handle(lua_State* L, ecs::Entity e, const char* meta) {
  auto* p = static_cast<ecs::Entity*>(lua_newuserdatauv(L, sizeof(ecs::Entity), 0));
  *p = e;
  luaL_setmetatable(L, meta);
}

int push_vec3(lua_State* L, const glm::vec3& v) {
  lua_pushnumber(L, v.x);
  lua_pushnumber(L, v.y);
  lua_pushnumber(L, v.z);
  return 3;
}

// --- transform ---------------------------------------------------------------

int t_get_position(lua_State* L) { return push_vec3(L, transform_of(L).translation); }
int t_set_position(lua_State* L) {
  const glm::vec3 p(check_finite(L, 2, "x"), check_finite(L, 3, "y"), check_finite(L, 4, "z"));
  transform_of(L).translation = p;
  return 0;
}
int t_translate(lua_State* L) {
  const glm::vec3 d(check_finite(L, 2, "dx"), check_finite(L, 3, "dy"), check_finite(L, 4, "dz"));
  transform_of(L).translation += d;
  return 0;
}
int t_rotate(lua_State* L) {
  glm::quat q;
  if (lua_gettop(L) >= 3) {  // rotate(axis, radians)
    const glm::vec3 axis = check_vec3(L, 2, "axis");
    const float len = glm::length(axis);
    if (!(len > 1e-12f)) luaL_error(L, "rotate: the axis has zero length");
    q = glm::angleAxis(check_finite(L, 3, "radians"), axis / len);
  } else {  // rotate(euler)
    q = glm::quat(check_vec3(L, 2, "euler"));
  }
  transform::Transform& t = transform_of(L);
  t.rotation = glm::normalize(q * t.rotation);
  return 0;
}
int t_get_rotation(lua_State* L) { return push_vec3(L, glm::eulerAngles(transform_of(L).rotation)); }
int t_set_rotation(lua_State* L) {
  const glm::quat q(check_vec3(L, 2, "euler"));
  transform_of(L).rotation = glm::normalize(q);
  return 0;
}
int t_get_scale(lua_State* L) {
  lua_pushnumber(L, transform_of(L).scale);
  return 1;
}
int t_set_scale(lua_State* L) {
  const float s = check_finite(L, 2, "scale");
  if (!(s > 0)) luaL_error(L, "set_scale: the scale must be positive, got %f", static_cast<double>(s));
  transform_of(L).scale = s;
  return 0;
}
int t_get_forward(lua_State* L) {  // world-space -Z: where a camera or light points
  const ecs::Entity e = live(L, 1, kTransformMeta);
  const auto* w = context_of(L).world->try_get<transform::WorldTransform>(e);
  const glm::quat q = w ? w->rotation : transform_of(L).rotation;
  return push_vec3(L, q * glm::vec3(0.0f, 0.0f, -1.0f));
}
int t_get_world_position(lua_State* L) {
  const ecs::Entity e = live(L, 1, kTransformMeta);
  const auto* w = context_of(L).world->try_get<transform::WorldTransform>(e);
  return push_vec3(L, w ? w->translation : transform_of(L).translation);
}

// --- light -------------------------------------------------------------------

int l_set_intensity(lua_State* L) {
  const float v = check_finite(L, 2, "intensity");
  if (v < 0) luaL_error(L, "set_intensity: intensity must be >= 0, got %f", static_cast<double>(v));
  light_of(L).intensity = v;
  return 0;
}
int l_get_intensity(lua_State* L) {
  lua_pushnumber(L, light_of(L).intensity);
  return 1;
}
int l_set_color(lua_State* L) {
  const glm::vec3 c(check_finite(L, 2, "r"), check_finite(L, 3, "g"), check_finite(L, 4, "b"));
  if (glm::any(glm::lessThan(c, glm::vec3(0.0f)))) luaL_error(L, "set_color: components must be >= 0");
  light_of(L).color = c;
  return 0;
}
int l_set_enabled(lua_State* L) {
  luaL_checktype(L, 2, LUA_TBOOLEAN);
  light_of(L).enabled = lua_toboolean(L, 2) != 0;
  return 0;
}
int l_is_enabled(lua_State* L) {
  lua_pushboolean(L, light_of(L).enabled);
  return 1;
}
int l_set_range(lua_State* L) {
  const float r = check_finite(L, 2, "range");
  if (r < 0) luaL_error(L, "set_range: range must be >= 0 (0 = infinite)");
  light_of(L).range = r;
  return 0;
}

// --- entity ------------------------------------------------------------------

int e_alive(lua_State* L) {
  lua_pushboolean(L, context_of(L).world->alive(handle_at(L, 1, kEntityMeta)));
  return 1;
}

int e_index(lua_State* L) {
  const ecs::Entity e = handle_at(L, 1, kEntityMeta);
  const char* key = luaL_checkstring(L, 2);
  const std::string k(key);
  if (k == "transform") {
    push_handle(L, e, kTransformMeta);
  } else if (k == "light") {
    push_handle(L, e, kLightMeta);
  } else if (k == "name") {
    const ecs::World& w = *context_of(L).world;
    const auto* n = w.alive(e) ? w.try_get<scene::Name>(e) : nullptr;
    if (n) lua_pushlstring(L, n->value.data(), n->value.size());
    else lua_pushnil(L);
  } else if (k == "index") {
    lua_pushinteger(L, e.index);
  } else if (k == "alive") {
    lua_pushcfunction(L, e_alive);
  } else {
    lua_pushnil(L);
  }
  return 1;
}

int e_eq(lua_State* L) {
  lua_pushboolean(L, handle_at(L, 1, kEntityMeta) == handle_at(L, 2, kEntityMeta));
  return 1;
}

int e_tostring(lua_State* L) {
  const ecs::Entity e = handle_at(L, 1, kEntityMeta);
  lua_pushfstring(L, "Entity(%d:%d)", static_cast<int>(e.index), static_cast<int>(e.generation));
  return 1;
}

void new_methods_meta(lua_State* L, const char* name, const luaL_Reg* methods) {
  luaL_newmetatable(L, name);
  lua_newtable(L);
  luaL_setfuncs(L, methods, 0);
  lua_setfield(L, -2, "__index");
  lua_pushstring(L, name);
  lua_setfield(L, -2, "__name");
  lua_pop(L, 1);
}

}  // namespace

float check_finite(lua_State* L, int index, const char* what) {
  const lua_Number v = luaL_checknumber(L, index);
  if (!std::isfinite(v) || std::abs(v) > 1e30) luaL_error(L, "%s must be a finite number, got %f", what, static_cast<double>(v));
  return static_cast<float>(v);
}

glm::vec3 check_vec3(lua_State* L, int index, const char* what) {
  luaL_checktype(L, index, LUA_TTABLE);
  glm::vec3 v;
  const char* named[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    if (lua_getfield(L, index, named[i]) == LUA_TNIL) {
      lua_pop(L, 1);
      lua_rawgeti(L, index, i + 1);
    }
    if (!lua_isnumber(L, -1)) luaL_error(L, "%s: expected {x, y, z} or {x=, y=, z=} numbers", what);
    const lua_Number n = lua_tonumber(L, -1);
    lua_pop(L, 1);
    if (!std::isfinite(n) || std::abs(n) > 1e30) luaL_error(L, "%s: component %d is not a finite number", what, i + 1);
    v[i] = static_cast<float>(n);
  }
  return v;
}

ecs::Entity check_entity(lua_State* L, int index) { return handle_at(L, index, kEntityMeta); }

void push_entity(lua_State* L, ecs::Entity e) { push_handle(L, e, kEntityMeta); }

void register_entity_types(lua_State* L) {
  const luaL_Reg transform_methods[] = {{"get_position", t_get_position}, {"set_position", t_set_position},
                                        {"translate", t_translate},       {"rotate", t_rotate},
                                        {"get_rotation", t_get_rotation}, {"set_rotation", t_set_rotation},
                                        {"get_scale", t_get_scale},       {"set_scale", t_set_scale},
                                        {"get_world_position", t_get_world_position},
                                        {"get_forward", t_get_forward}, {nullptr, nullptr}};
  const luaL_Reg light_methods[] = {{"set_intensity", l_set_intensity}, {"get_intensity", l_get_intensity},
                                    {"set_color", l_set_color},         {"set_enabled", l_set_enabled},
                                    {"is_enabled", l_is_enabled},       {"set_range", l_set_range},
                                    {nullptr, nullptr}};
  new_methods_meta(L, kTransformMeta, transform_methods);
  new_methods_meta(L, kLightMeta, light_methods);
  luaL_newmetatable(L, kEntityMeta);
  const luaL_Reg entity_meta[] = {{"__index", e_index}, {"__eq", e_eq}, {"__tostring", e_tostring}, {nullptr, nullptr}};
  luaL_setfuncs(L, entity_meta, 0);
  lua_pop(L, 1);
}

}  // namespace engine::script::detail
