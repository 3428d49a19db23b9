#pragma once
// The machine's own ceilings, measured in the calling process so that a
// stage's "percentage of the floor" compares numbers taken under the same
// clock and load (these VMs are noisy): arithmetic peaks from register-only
// loops on every job-system thread, and Embree's rate on incoherent rays.
#include "engine/rt/rt_scene.h"

namespace transgi::eval {

struct MachinePeak {
  double bf16_gflops = 0;  // vdpbf16ps (0 where the CPU has no AVX-512 BF16)
  double amx_gflops = 0;   // AMX bf16 tile products (0 where the CPU or OS has no AMX)
  double fp32_gflops = 0;  // FMA, AVX-512 where present, else AVX2
  double incoherent_mrays = 0;  // closest-hit rays/s from random points in random directions
};

// Runs for about `seconds` in all; call inside the job system's arena so the
// loops use every worker.
MachinePeak measure_machine_peak(const engine::rt::RtScene& scene, double seconds = 0.6);

// One thread's bf16 peak loop: `reps` x 24 vdpbf16ps, 64 FLOP each.
double bf16_peak_loop(long long reps);
// One thread's AMX peak loop: `reps` x 4 tile products, 16,384 FLOP each.
double amx_peak_loop(long long reps);

}  // namespace transgi::eval
