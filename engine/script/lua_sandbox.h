#pragma once
// A Lua 5.4 state for untrusted gameplay scripts:
//  - only base, math, string, table, utf8 and coroutine are opened, and
//    load, loadfile, dofile, require, collectgarbage and string.dump are
//    removed, so a script reaches nothing outside the engine's API;
//  - chunks are compiled from text only (never precompiled bytecode, which
//    Lua does not verify);
//  - memory is capped by the allocator, in all and per owner (a script): each
//    block carries the owner that allocated it, so a script that leaks hits
//    its own budget, with an error at its own line, and leaves the rest of
//    the memory to the others;
//  - every call into the script runs under an instruction budget, so an
//    endless loop ends with an error;
//  - calls run under pcall with a traceback as the message.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

struct lua_State;

namespace engine::script {

struct SandboxLimits {
  // Higher = longer hooks allowed at the cost of a later stop for a runaway one.
  int instruction_budget = 5'000'000;
  // All scripts together. Higher = more script data in all, at the cost of
  // the game's memory.
  std::size_t memory_bytes = std::size_t{256} << 20;
  // One script (one owner). Higher = bigger data per script, at the cost of
  // how much of memory_bytes one leaking script can take from the others.
  std::size_t owner_memory_bytes = std::size_t{64} << 20;
};

class LuaSandbox {
 public:
  explicit LuaSandbox(SandboxLimits limits = {});
  ~LuaSandbox();
  LuaSandbox(const LuaSandbox&) = delete;
  LuaSandbox& operator=(const LuaSandbox&) = delete;

  [[nodiscard]] lua_State* state() const { return L_; }
  [[nodiscard]] const SandboxLimits& limits() const { return limits_; }
  // Bytes held by every owner, and by one (0: the engine's own: libraries,
  // the API, whatever runs outside an owner's scope).
  [[nodiscard]] std::size_t memory_used() const { return alloc_.used; }
  [[nodiscard]] std::size_t memory_used(std::uint32_t owner) const {
    return owner < alloc_.owner_used.size() ? alloc_.owner_used[owner] : 0;
  }

  // A new owner id (a script instance), with nothing allocated yet.
  std::uint32_t add_owner();
  // While it lives, what Lua allocates is charged to `owner`; an owner past
  // owner_memory_bytes gets a Lua error ("memory budget exceeded") at its
  // next instruction, where it is running, so the message has its file and
  // line. Frees are charged to whoever allocated the block.
  class OwnerScope {
   public:
    OwnerScope(LuaSandbox& sandbox, std::uint32_t owner);
    ~OwnerScope();
    OwnerScope(const OwnerScope&) = delete;
    OwnerScope& operator=(const OwnerScope&) = delete;

   private:
    LuaSandbox& sandbox_;
    std::uint32_t previous_;
  };
  // A full garbage collection (after the engine dropped a script's tables).
  void collect() const;

  // Pushes a new environment table whose reads fall back to the sandbox's
  // globals; each script gets its own, so its globals are its own.
  void push_new_env() const;
  // The shared globals (libraries and the engine API) on top of the stack.
  void push_globals() const;

  // Compiles `source` in text mode and sets the environment table at stack
  // index env_index as its _ENV. On success pushes the function and returns
  // ""; on failure pushes nothing and returns the message.
  std::string load(std::string_view source, const std::string& chunk_name, int env_index) const;

  // Calls the function below `nargs` arguments on the stack under the
  // instruction budget and a traceback handler. Pops them; on success
  // leaves nresults results and returns ""; on failure leaves nothing and
  // returns the message with its traceback.
  std::string call(int nargs, int nresults) const;

 private:
  struct Alloc {
    std::size_t used = 0, limit = 0, owner_limit = 0;
    std::vector<std::size_t> owner_used;  // by owner id
    std::uint32_t current = 0;           // whom allocations are charged to now
    lua_State* L = nullptr;              // set once the state exists
  };
  static void* allocate(void* ud, void* ptr, std::size_t old_size, std::size_t new_size);

  SandboxLimits limits_;
  Alloc alloc_;
  lua_State* L_ = nullptr;
  int globals_ref_ = 0;
};

}  // namespace engine::script
