#pragma once
// Ranks as threads of one process: the distributed bake's exchange without
// MPI, so tests can run N ranks deterministically in one test binary, and the
// bake's logic is tested where the build has no MPI.
#include <memory>

#include "bake/communicator.h"

namespace transgi::bake {

// `size` communicators sharing one exchange; hand communicator r to the
// thread that plays rank r. Each must be used from its own thread only.
std::vector<std::unique_ptr<Communicator>> make_thread_group(int size);

}  // namespace transgi::bake
