#pragma once
// Turns a plain function (or a capture-less or capturing lambda with a
// non-template call operator) into a schedulable system.
#include <functional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "engine/schedule/system_param.h"

namespace engine::schedule {

struct System {
  std::string name;
  Access access;
  std::function<void(World&, SystemState&)> init;
  std::function<void(World&, SystemState&)> run;
};

namespace detail {
template <class F>
struct FunctionTraits : FunctionTraits<decltype(&F::operator())> {};
template <class R, class... Args>
struct FunctionTraits<R (*)(Args...)> {
  using ArgsTuple = std::tuple<Args...>;
};
template <class R, class... Args>
struct FunctionTraits<R(Args...)> {
  using ArgsTuple = std::tuple<Args...>;
};
template <class C, class R, class... Args>
struct FunctionTraits<R (C::*)(Args...) const> {
  using ArgsTuple = std::tuple<Args...>;
};
template <class C, class R, class... Args>
struct FunctionTraits<R (C::*)(Args...)> {
  using ArgsTuple = std::tuple<Args...>;
};

template <class Fn, class... Args, std::size_t... I>
System make_system_impl(std::string name, Fn fn, std::tuple<Args...>*, std::index_sequence<I...>) {
  System s;
  s.name = std::move(name);
  (Param<ParamKey<Args>>::declare(s.access), ...);
  s.init = [](World& w, SystemState& st) { (Param<ParamKey<Args>>::init(w, st, I), ...); };
  s.run = [fn = std::move(fn)](World& w, SystemState& st) mutable {
    fn(Param<ParamKey<Args>>::fetch(w, st, I)...);
  };
  return s;
}
}  // namespace detail

template <class Fn>
System make_system(std::string name, Fn fn) {
  using Traits = detail::FunctionTraits<std::decay_t<Fn>>;
  using ArgsTuple = typename Traits::ArgsTuple;
  return detail::make_system_impl(std::move(name), std::move(fn), static_cast<ArgsTuple*>(nullptr),
                                  std::make_index_sequence<std::tuple_size_v<ArgsTuple>>{});
}

}  // namespace engine::schedule
