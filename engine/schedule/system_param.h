#pragma once
// System parameters. A system is a plain function; the scheduler inspects its
// parameter types to learn its access and to build its arguments each run:
//
//   View<Get<const A, B>, Exclude<C>>  reads A, writes B, reads C's presence
//   Res<T> / ResMut<T>                 reads / writes resource T
//   Commands&                          deferred structural changes (no access)
//   Removed<T>                         entities whose T went away since last run
//   Local<T>                           state private to this system
//   SystemTicks                        this system's last_run / this_run
//   World& / const World&              exclusive / read-everything access
#include <any>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "engine/ecs/commands.h"
#include "engine/ecs/view.h"
#include "engine/ecs/world.h"
#include "engine/schedule/access.h"

namespace engine::schedule {

using ecs::Commands;
using ecs::Entity;
using ecs::Exclude;
using ecs::Get;
using ecs::Tick;
using ecs::View;
using ecs::World;

// Per-system bookkeeping that outlives a single run.
struct SystemState {
  std::string name;
  Tick last_run = 0;
  Tick this_run = 0;
  Commands commands;
  std::vector<std::shared_ptr<void>> locals;  // one slot per parameter index
};

template <class T>
class Res {
 public:
  explicit Res(const T& v) : v_(&v) {}
  const T& operator*() const { return *v_; }
  const T* operator->() const { return v_; }

 private:
  const T* v_;
};

template <class T>
class ResMut {
 public:
  explicit ResMut(T& v) : v_(&v) {}
  T& operator*() const { return *v_; }
  T* operator->() const { return v_; }

 private:
  T* v_;
};

template <class T>
class Local {
 public:
  explicit Local(T& v) : v_(&v) {}
  T& operator*() const { return *v_; }
  T* operator->() const { return v_; }

 private:
  T* v_;
};

template <class T>
struct Removed {
  std::vector<Entity> entities;
  [[nodiscard]] bool empty() const { return entities.empty(); }
  [[nodiscard]] auto begin() const { return entities.begin(); }
  [[nodiscard]] auto end() const { return entities.end(); }
};

struct SystemTicks {
  Tick last_run;
  Tick this_run;
};

// Thrown when a system's resource is missing at run time.
class ScheduleError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

template <class P>
struct Param {
  static_assert(sizeof(P) == 0,
                "unsupported system parameter: use View<...>, Res<T>, ResMut<T>, Commands&, Removed<T>, Local<T>, "
                "SystemTicks, World& or const World&");
};

template <class... Ts, class... Xs>
struct Param<View<Get<Ts...>, Exclude<Xs...>>> {
  static void declare(Access& a) {
    ((std::is_const_v<Ts> ? a.component_reads : a.component_writes)
         .push_back(ecs::type_id<std::remove_const_t<Ts>>()),
     ...);
    (a.component_reads.push_back(ecs::type_id<Xs>()), ...);
  }
  static void init(World& w, SystemState&, std::size_t) {
    (w.storage<std::remove_const_t<Ts>>(), ...);
    (w.storage<Xs>(), ...);
  }
  static View<Get<Ts...>, Exclude<Xs...>> fetch(World& w, SystemState& s, std::size_t) {
    return View<Get<Ts...>, Exclude<Xs...>>(w, s.last_run, s.this_run);
  }
};

template <class T>
struct Param<Res<T>> {
  static void declare(Access& a) { a.resource_reads.push_back(ecs::type_id<T>()); }
  static void init(World&, SystemState&, std::size_t) {}
  static Res<T> fetch(World& w, SystemState& s, std::size_t) {
    if (const T* p = w.try_resource<T>()) return Res<T>(*p);
    throw ScheduleError("system '" + s.name + "' needs resource " + std::string(ecs::type_name<T>()) +
                        ", which was never inserted");
  }
};

template <class T>
struct Param<ResMut<T>> {
  static void declare(Access& a) { a.resource_writes.push_back(ecs::type_id<T>()); }
  static void init(World&, SystemState&, std::size_t) {}
  static ResMut<T> fetch(World& w, SystemState& s, std::size_t) {
    if (T* p = w.try_resource<T>()) return ResMut<T>(*p);
    throw ScheduleError("system '" + s.name + "' needs resource " + std::string(ecs::type_name<T>()) +
                        ", which was never inserted");
  }
};

template <class T>
struct Param<Local<T>> {
  static void declare(Access&) {}
  static void init(World&, SystemState& s, std::size_t i) {
    if (s.locals.size() <= i) s.locals.resize(i + 1);
    if (!s.locals[i]) s.locals[i] = std::make_shared<T>();
  }
  static Local<T> fetch(World&, SystemState& s, std::size_t i) { return Local<T>(*static_cast<T*>(s.locals[i].get())); }
};

template <class T>
struct Param<Removed<T>> {
  static void declare(Access&) {}  // the removal log only changes at sync points
  static void init(World& w, SystemState&, std::size_t) { w.storage<T>(); }
  static Removed<T> fetch(World& w, SystemState& s, std::size_t) { return {w.removed_since<T>(s.last_run)}; }
};

template <>
struct Param<SystemTicks> {
  static void declare(Access&) {}
  static void init(World&, SystemState&, std::size_t) {}
  static SystemTicks fetch(World&, SystemState& s, std::size_t) { return {s.last_run, s.this_run}; }
};

template <>
struct Param<Commands&> {
  static void declare(Access&) {}
  static void init(World& w, SystemState& s, std::size_t) { s.commands = Commands(w); }
  static Commands& fetch(World&, SystemState& s, std::size_t) { return s.commands; }
};

template <>
struct Param<World&> {
  static void declare(Access& a) { a.exclusive = true; }
  static void init(World&, SystemState&, std::size_t) {}
  static World& fetch(World& w, SystemState&, std::size_t) { return w; }
};

template <>
struct Param<const World&> {
  static void declare(Access& a) { a.reads_all = true; }
  static void init(World&, SystemState&, std::size_t) {}
  static const World& fetch(World& w, SystemState&, std::size_t) { return w; }
};

// Reference parameters keep their reference (World&, Commands&); everything
// else is matched by its plain value type.
template <class A>
using ParamKey = std::conditional_t<std::is_reference_v<A> &&
                                        (std::is_same_v<std::remove_cvref_t<A>, World> ||
                                         std::is_same_v<std::remove_cvref_t<A>, Commands>),
                                    A, std::remove_cvref_t<A>>;

}  // namespace engine::schedule
