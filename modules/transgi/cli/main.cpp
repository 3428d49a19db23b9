// transgi: one executable for rendering, comparing, baking and evaluating.
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "cli/args.h"
#include "cli/commands.h"
#include "engine/core/cpu_isa.h"
#include "engine/gpu/vulkan_context.h"

namespace {
constexpr const char* kUsage =
    "usage: transgi <command> [options]\n"
    "  render   --scene S.gltf --out F.exr [--method reference|transgi|ddgi] [options]: transgi render --help\n"
    "  compare  A.exr B.exr [--heatmap out.png] [--heatmap-max E] [--colour [--colour-mask R_textured.exr] [--albedo R_albedo.exr]] [--edge-band-of R_direct.exr [--band PX]]\n"
    "           [--top-error PERCENT] [--downsample N (every metric over N x N block means)]\n"
    "  tonemap  IN.exr OUT.png [--exposure EV] [--signed SCALE] [--minus B.exr]\n"
    "  bake     --scene S.gltf --out M.tgm [--points N] [--dirs D] [--outgoing K] [--iters I] [--batch B]\n"
    "           [--max-points-per-vertex P (default 8192; 0 = by area alone)]\n"
    "           [--lr R] [--latent-dim K] [--width W] [--depth L] [--threads T] [--seed S] [--resume] [--keep-dataset]\n"
    "           [--latent-updates all|touched (default all; touched: Adam moves only the latent rows a step touched)]\n"
    "           [--gradient-blocks G (default 8, a power of two: bakes on 1, 2, 4, ... G ranks or any --threads are bit for bit alike;\n"
    "           a rank's threads share the G blocks)]\n"
    "           under mpirun or srun (a build with MPI): one bake on every rank, --threads each (default: the\n"
    "           machine's cores shared by its ranks)\n"
    "  transfer-study --scene S.gltf [--points N] [--outgoing K] [--reference-rays R]\n"
    "  eval     --scene S.gltf --model M.tgm --out DIR [--width W --height H --spp N --frames F --ddgi-frames F2]\n"
    "           [--probe-grid N] [--cache DIR] [--reference-error E] [--temporal N] [--decompose]\n"
    "  bench-pareto --scene S.gltf --model M.tgm --out DIR [--width W --height H --spp N] [--quick]\n"
    "  bench-frame --scene S.gltf --model M.tgm [options]: transgi bench-frame --help\n"
    "  sun-sweep --scene S.gltf --model M.tgm --out DIR [--positions 8 --frames 96 --warmup 96 --elevation-from E0\n"
    "           --elevation-to E1 --azimuth-from A0 --azimuth-to A1 --reference-spp N --settle-tolerance 0.05]\n"
    "  fly-through --scene S.gltf --model M.tgm --out DIR --path x,y,z;x,y,z;... [--frames 300 --stops F1,F2,F3\n"
    "           --reference-spp N --pitch DEG]\n"
    "  eval also takes: --probe-volume cascades|scene|authored (default cascades; a scene small\n"
    "           enough for 2 m cells gets one grid over it) [--cascades N] [--cascade-cell M] [--cascade-look-ahead F]\n"
    "           [--cascade-fit-scene M], and --allow-unbaked (meshes added after the bake are shaded diffusely)\n"
    "  eval also takes --near-field-rays N --near-field-reach CELLS --near-field-filter RADIUS (contact light)\n"
    "  transgi --version; transgi COMMAND --help lists every option COMMAND accepts\n"
    "exit codes: 0 done; 1 a bad or missing input file, or a failure while running (the message names it);\n"
    "  2 a bad command line\n";

void usage() { std::fputs(kUsage, stderr); }

// The usage lines of one command: from its "  command " line to the next command's.
std::string usage_of(const std::string& command) {
  std::string out, line;
  bool in = false;
  for (const char* c = kUsage;; ++c) {
    if (*c != '\n' && *c != '\0') {
      line += *c;
      continue;
    }
    const bool starts_command = line.size() > 2 && line[0] == ' ' && line[1] == ' ' && line[2] != ' ';
    if (starts_command) in = line.rfind("  " + command + " ", 0) == 0;
    if (in) out += line + "\n";
    line.clear();
    if (*c == '\0') break;
  }
  return out;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage();
    return 2;
  }
  const std::string command = argv[1];
  const std::vector<std::string> args(argv + 2, argv + argc);
  try {
    if (command == "render") return transgi::cli::run_render(args);
    if (command == "compare") return transgi::cli::run_compare(args);
    if (command == "tonemap") return transgi::cli::run_tonemap(args);
    if (command == "bake") return transgi::cli::run_bake(args);
    if (command == "transfer-study") return transgi::cli::run_transfer_study(args);
    if (command == "eval") return transgi::cli::run_eval(args);
    if (command == "bench-pareto") return transgi::cli::run_bench_pareto(args);
    if (command == "bench-frame") return transgi::cli::run_bench_frame(args);
    if (command == "sun-sweep") return transgi::cli::run_sun_sweep(args);
    if (command == "fly-through") return transgi::cli::run_fly_through(args);
    if (command == "--help" || command == "help") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (command == "--version") {
      // The version, then what this machine offers the frame: the CPU's
      // instruction sets (and any TRANSGI_MAX_ISA cap) and the Vulkan device
      // the GPU backend would take, or why there is none.
      std::printf("transgi %s\ncpu: %s\n", TRANSGI_VERSION, engine::cpu::isa_summary().c_str());
      std::string why;
      const auto gpu = engine::gpu::VulkanContext::create(engine::gpu::GpuOptions{}, &why);
      std::printf("gpu: %s\n", gpu ? engine::gpu::describe(gpu->info()).c_str() : ("none (" + why + "): the cpu backend").c_str());
      return 0;
    }
    std::fprintf(stderr, "transgi: unknown command '%s'\n", command.c_str());
    usage();
    return 2;
  } catch (const engine::core::HelpRequested& e) {
    if (e.complete())
      std::fputs(e.what(), stdout);
    else
      std::printf("usage:\n%s%s", usage_of(command).c_str(), e.what());
    return 0;
  } catch (const transgi::cli::UsageError& e) {
    std::fprintf(stderr, "transgi %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "transgi %s: %s\n", command.c_str(), e.what());
    return 1;
  }
}
