// Fixture: a wrong-way include the checker must reject.
#include <game/level.h>
int x;
