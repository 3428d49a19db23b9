#pragma once
// Umbrella header for the ECS core.
#include "engine/ecs/commands.h"
#include "engine/ecs/entity.h"
#include "engine/ecs/view.h"
#include "engine/ecs/world.h"
