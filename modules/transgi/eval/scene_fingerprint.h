#pragma once
// A 64-bit fingerprint of everything a render of the loaded scene depends
// on: mesh geometry and materials (and their textures), instance placement,
// lights, the environment and the cameras. Cached reference renders are keyed
// by it together with the render settings, so an edited scene never reuses a
// stale reference.
#include <cstdint>
#include <string>

#include "engine/ecs/world.h"

namespace transgi::eval {

std::uint64_t scene_fingerprint(engine::ecs::World& world);
std::string hex64(std::uint64_t v);

}  // namespace transgi::eval
