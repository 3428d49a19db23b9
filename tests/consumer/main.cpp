// The smallest game on TransGI: it only has to compile and link against the
// module's targets (the configure test does not build it).
#include "runtime/transgi_plugin.h"

int main() { return 0; }
