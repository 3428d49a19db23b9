#pragma once
// A Lua 5.4 state for untrusted gameplay scripts:
//  - only base, math, string, table, utf8 and coroutine are opened, and
//    load, loadfile, dofile, require, collectgarbage and string.dump are
//    removed, so a script reaches nothing outside the engine's API;
//  - chunks are compiled from text only (never precompiled bytecode, which
//    Lua does not verify);
//  - memory is capped by the allocator, and every call into the script runs
//    under an instruction budget, so an endless loop ends with an error;
//  - calls run under pcall with a traceback as the message.
#include <cstddef>
#include <string>
#include <string_view>

struct lua_State;

namespace engine::script {

struct SandboxLimits {
  // Higher = longer hooks allowed at the cost of a later stop for a runaway one.
  int instruction_budget = 5'000'000;
  // Higher = bigger script data allowed at the cost of memory a script may take.
  std::size_t memory_bytes = std::size_t{256} << 20;
};

class LuaSandbox {
 public:
  explicit LuaSandbox(SandboxLimits limits = {});
  ~LuaSandbox();
  LuaSandbox(const LuaSandbox&) = delete;
  LuaSandbox& operator=(const LuaSandbox&) = delete;

  [[nodiscard]] lua_State* state() const { return L_; }
  [[nodiscard]] const SandboxLimits& limits() const { return limits_; }
  [[nodiscard]] std::size_t memory_used() const { return alloc_.used; }

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
    std::size_t used = 0, limit = 0;
  };
  static void* allocate(void* ud, void* ptr, std::size_t old_size, std::size_t new_size);

  SandboxLimits limits_;
  Alloc alloc_;
  lua_State* L_ = nullptr;
  int globals_ref_ = 0;
};

}  // namespace engine::script
