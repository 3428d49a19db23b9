#pragma once
// Helpers shared by the Lua API files (private to engine/script).
#include <glm/glm.hpp>

#include "engine/ecs/entity.h"

struct lua_State;

namespace engine::script::detail {

// A finite number at `index`, or a Lua error naming `what`.
float check_finite(lua_State* L, int index, const char* what);
// {x, y, z} or {x=, y=, z=} at `index`, each finite, or a Lua error.
glm::vec3 check_vec3(lua_State* L, int index, const char* what);
// The entity handle at `index` (alive or not), or a Lua error.
ecs::Entity check_entity(lua_State* L, int index);
// Creates the Entity, Transform and Light metatables.
void register_entity_types(lua_State* L);

}  // namespace engine::script::detail
