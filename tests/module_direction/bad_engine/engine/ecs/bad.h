#pragma once
// Fixture: a wrong-way include the checker must reject.
#include "transgi/probe_volume.h"
