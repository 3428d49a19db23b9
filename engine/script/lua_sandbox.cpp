#include "engine/script/lua_sandbox.h"

#include <cstdlib>
#include <stdexcept>

#include <lua.hpp>

namespace engine::script {

namespace {

// Registry key of the sandbox's budget, read by the count hook.
char kBudgetKey;

void budget_exceeded(lua_State* L, lua_Debug*) {
  // Off first, so the traceback handler that runs next is not stopped too.
  lua_sethook(L, nullptr, 0, 0);
  lua_rawgetp(L, LUA_REGISTRYINDEX, &kBudgetKey);
  const lua_Integer budget = lua_tointeger(L, -1);
  lua_pop(L, 1);
  luaL_error(L, "instruction budget exceeded (%I instructions in one call): an endless loop?", budget);
}

int traceback(lua_State* L) {
  const char* message = lua_tostring(L, 1);
  if (!message) message = luaL_tolstring(L, 1, nullptr);
  luaL_traceback(L, L, message, 1);
  return 1;
}

}  // namespace

void* LuaSandbox::allocate(void* ud, void* ptr, std::size_t old_size, std::size_t new_size) {
  auto* a = static_cast<Alloc*>(ud);
  const std::size_t old_bytes = ptr ? old_size : 0;  // with no block, old_size names a type
  if (new_size == 0) {
    std::free(ptr);
    a->used -= old_bytes;
    return nullptr;
  }
  if (new_size > old_bytes && a->used - old_bytes + new_size > a->limit) return nullptr;  // Lua raises "not enough memory"
  void* p = std::realloc(ptr, new_size);
  if (p) a->used = a->used - old_bytes + new_size;
  return p;
}

LuaSandbox::LuaSandbox(SandboxLimits limits) : limits_(limits) {
  if (limits_.instruction_budget < 1000) throw std::invalid_argument("LuaSandbox: instruction_budget must be at least 1000");
  alloc_.limit = limits_.memory_bytes;
  L_ = lua_newstate(&LuaSandbox::allocate, &alloc_);
  if (!L_) throw std::runtime_error("LuaSandbox: could not create a Lua state");
  const luaL_Reg libs[] = {{LUA_GNAME, luaopen_base},       {LUA_MATHLIBNAME, luaopen_math}, {LUA_STRLIBNAME, luaopen_string},
                           {LUA_TABLIBNAME, luaopen_table}, {LUA_UTF8LIBNAME, luaopen_utf8}, {LUA_COLIBNAME, luaopen_coroutine}};
  for (const luaL_Reg& lib : libs) {
    luaL_requiref(L_, lib.name, lib.func, 1);
    lua_pop(L_, 1);
  }
  lua_pushglobaltable(L_);
  for (const char* name : {"load", "loadfile", "dofile", "require", "collectgarbage"}) {
    lua_pushnil(L_);
    lua_setfield(L_, -2, name);
  }
  lua_getfield(L_, -1, LUA_STRLIBNAME);
  lua_pushnil(L_);
  lua_setfield(L_, -2, "dump");  // bytecode out is harmless without load, but there is no use for it
  lua_pop(L_, 1);
  globals_ref_ = luaL_ref(L_, LUA_REGISTRYINDEX);  // pops the global table
  lua_pushinteger(L_, limits_.instruction_budget);
  lua_rawsetp(L_, LUA_REGISTRYINDEX, &kBudgetKey);
}

LuaSandbox::~LuaSandbox() {
  if (L_) lua_close(L_);
}

void LuaSandbox::push_globals() const { lua_rawgeti(L_, LUA_REGISTRYINDEX, globals_ref_); }

void LuaSandbox::push_new_env() const {
  lua_newtable(L_);               // env
  lua_createtable(L_, 0, 1);      // its metatable
  push_globals();
  lua_setfield(L_, -2, "__index");
  lua_setmetatable(L_, -2);
}

std::string LuaSandbox::load(std::string_view source, const std::string& chunk_name, int env_index) const {
  env_index = lua_absindex(L_, env_index);
  const std::string name = "@" + chunk_name;
  if (luaL_loadbufferx(L_, source.data(), source.size(), name.c_str(), "t") != LUA_OK) {
    std::string message = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "unknown load error";
    lua_pop(L_, 1);
    return message;
  }
  lua_pushvalue(L_, env_index);
  if (!lua_setupvalue(L_, -2, 1)) lua_pop(L_, 1);  // a main chunk's first upvalue is _ENV
  return {};
}

std::string LuaSandbox::call(int nargs, int nresults) const {
  const int function_index = lua_gettop(L_) - nargs;
  lua_pushcfunction(L_, traceback);
  lua_insert(L_, function_index);
  lua_sethook(L_, budget_exceeded, LUA_MASKCOUNT, limits_.instruction_budget);
  const int status = lua_pcall(L_, nargs, nresults, function_index);
  lua_sethook(L_, nullptr, 0, 0);
  std::string message;
  if (status != LUA_OK) {
    message = lua_tostring(L_, -1) ? lua_tostring(L_, -1) : "error object is not a string";
    lua_pop(L_, 1);
  }
  lua_remove(L_, function_index);
  return message;
}

}  // namespace engine::script
