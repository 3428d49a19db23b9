#include "engine/script/lua_sandbox.h"

#include <cstdlib>
#include <stdexcept>

#include <lua.hpp>

namespace engine::script {

namespace {

// Registry key of the sandbox's budget, read by the count hook.
char kBudgetKey;

void budget_exceeded(lua_State* L, lua_Debug* ar) {
  // Off first, so the traceback handler that runs next is not stopped too.
  lua_sethook(L, nullptr, 0, 0);
  lua_rawgetp(L, LUA_REGISTRYINDEX, &kBudgetKey);
  const lua_Integer budget = lua_tointeger(L, -1);
  lua_pop(L, 1);
  lua_getinfo(L, "Sl", ar);  // where the loop is: the running function's file and line
  lua_pushfstring(L, "%s:%d: instruction budget exceeded (%I instructions in one call): an endless loop?", ar->short_src,
                  ar->currentline, budget);
  lua_error(L);
}

int traceback(lua_State* L) {
  const char* message = lua_tostring(L, 1);
  if (!message) message = luaL_tolstring(L, 1, nullptr);
  luaL_traceback(L, L, message, 1);
  return 1;
}

}  // namespace

namespace {

// Each block is preceded by a header that names its owner (16 bytes, so the
// block keeps malloc's alignment).
struct alignas(16) BlockHeader {
  std::uint32_t owner;
};
static_assert(sizeof(BlockHeader) == 16);

void owner_budget_exceeded(lua_State* L, lua_Debug* ar) {
  lua_sethook(L, nullptr, 0, 0);  // off first, so the traceback handler runs freely
  // The hook's record is the running function: its file and line lead the
  // message, as luaL_error's would in the script itself.
  lua_getinfo(L, "Sl", ar);
  lua_pushfstring(L, "%s:%d: memory budget exceeded: this script holds more than its share "
                     "(SandboxLimits::owner_memory_bytes); a table that only grows?",
                  ar->short_src, ar->currentline);
  lua_error(L);
}

}  // namespace

void* LuaSandbox::allocate(void* ud, void* ptr, std::size_t old_size, std::size_t new_size) {
  auto* a = static_cast<Alloc*>(ud);
  BlockHeader* old_block = ptr ? static_cast<BlockHeader*>(ptr) - 1 : nullptr;
  const std::size_t old_bytes = ptr ? old_size : 0;  // with no block, old_size names a type
  const std::uint32_t old_owner = old_block ? old_block->owner : 0;
  if (new_size == 0) {
    std::free(old_block);
    a->used -= old_bytes;
    a->owner_used[old_owner] -= old_bytes;
    return nullptr;
  }
  // A block that grows is charged to whoever runs now; one that shrinks
  // stays with its owner.
  const std::uint32_t owner = new_size > old_bytes ? a->current : old_owner;
  if (new_size > old_bytes && a->used - old_bytes + new_size > a->limit) return nullptr;  // Lua raises "not enough memory"
  auto* block = static_cast<BlockHeader*>(std::realloc(old_block, sizeof(BlockHeader) + new_size));
  if (!block) return nullptr;
  a->used = a->used - old_bytes + new_size;
  a->owner_used[old_owner] -= old_bytes;
  a->owner_used[owner] += new_size;
  block->owner = owner;
  // Past its own budget: the script stops at its next instruction, with its
  // position in the message (no Lua call may run inside the allocator, but
  // lua_sethook may be called from anywhere).
  if (owner != 0 && a->owner_used[owner] > a->owner_limit && a->L) lua_sethook(a->L, owner_budget_exceeded, LUA_MASKCOUNT, 1);
  return block + 1;
}

std::uint32_t LuaSandbox::add_owner() {
  alloc_.owner_used.push_back(0);
  return static_cast<std::uint32_t>(alloc_.owner_used.size() - 1);
}

LuaSandbox::OwnerScope::OwnerScope(LuaSandbox& sandbox, std::uint32_t owner) : sandbox_(sandbox), previous_(sandbox.alloc_.current) {
  if (owner >= sandbox.alloc_.owner_used.size()) throw std::out_of_range("LuaSandbox::OwnerScope: no such owner");
  sandbox.alloc_.current = owner;
}
LuaSandbox::OwnerScope::~OwnerScope() { sandbox_.alloc_.current = previous_; }

void LuaSandbox::collect() const { lua_gc(L_, LUA_GCCOLLECT, 0); }

LuaSandbox::LuaSandbox(SandboxLimits limits) : limits_(limits) {
  if (limits_.instruction_budget < 1000) throw std::invalid_argument("LuaSandbox: instruction_budget must be at least 1000");
  alloc_.limit = limits_.memory_bytes;
  alloc_.owner_limit = limits_.owner_memory_bytes;
  alloc_.owner_used.assign(1, 0);  // owner 0: the engine
  L_ = lua_newstate(&LuaSandbox::allocate, &alloc_);
  if (!L_) throw std::runtime_error("LuaSandbox: could not create a Lua state");
  alloc_.L = L_;
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
