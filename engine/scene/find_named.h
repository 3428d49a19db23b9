#pragma once
// The entity whose Name is `name` (the first one in storage order if
// several share it), or the null entity. What scripts, level files and
// editors look entities up by.
#include <string_view>

#include "engine/ecs/world.h"
#include "engine/scene/components.h"

namespace engine::scene {

inline ecs::Entity find_named(ecs::World& world, std::string_view name) {
  ecs::Entity found;
  world.view<const Name>().each([&](ecs::Entity e, const Name& n) {
    if (found.is_null() && n.value == name) found = e;
  });
  return found;
}

}  // namespace engine::scene
