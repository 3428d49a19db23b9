#pragma once
// Tag lists that name a view's included and excluded components.
namespace engine::ecs {
template <class... Ts>
struct Get {};
template <class... Ts>
struct Exclude {};
template <class GetList, class ExcludeList = Exclude<>>
class View;
}  // namespace engine::ecs
