#!/usr/bin/env python3
"""The time a bake of a large level takes on C cores, from figures measured on
one machine (docs/bake.md, "Scaling: measured and modelled").

    scripts/bake_scaling_model.py [--vertices 10e6] [--cores 8,64,512]

Every constant below is either measured (the command is in docs/bake.md) or an
assumption, and says which. The model:

  sampling  = points * seconds_per_point / cores              (no exchange at all)
  a step    = batch * seconds_per_sample / cores              (forward, backward)
            + latent_floats * seconds_per_latent_float        (every rank, every step)
            + tree sum(decoder gradients) + allgather(latent rows)
  training  = steps * a step
"""
import argparse
import math

# Measured on the 2-core AMD EPYC (Zen 5, AVX-512) of docs/bake.md, one rank per core.
SECONDS_PER_POINT = 1 / 865.0      # sampling: 8 directions x 2000 rays, a rank's points/s
SECONDS_PER_SAMPLE = 55.3 / (20000 * 1024)  # training compute of a rank, per sample
# Zeroing the gradients, the finiteness check and the dense Adam update: per
# latent float, every step, on every rank (transgi_bench BM_TrainerStepByLatentTable).
SECONDS_PER_LATENT_FLOAT = 1.065e-9
# --latent-updates touched: the step's work on the latents follows the batch's
# rows instead (same benchmark, range(1) = 1: 5.3 -> 6.7 ms a step from 0.07 to
# 27.9 M latent floats, about 0.05 ns a latent float, from cache misses).
SECONDS_PER_LATENT_FLOAT_TOUCHED = 0.05e-9
DECODER_BYTES = 44875 * 4          # the default decoder's gradients
ROW_BYTES = 8 + 7 * 4              # a latent row on the wire: index + 7 floats

# Assumptions (docs/bake.md says why).
POINTS_PER_VERTEX = 1.0
SAMPLES_PER_POINT = 8
BATCH = 16384                      # 8x the default, so 512 cores still get 32 samples each
STEPS = 20000
CORES_PER_NODE = 32                # one rank per core
LATENCY = 5e-6                     # seconds a message, between nodes
BANDWIDTH = 12.5e9                 # bytes a second, between nodes (100 Gb/s)
SHARED_LATENCY = 1e-6              # within a node
SHARED_BANDWIDTH = 10e9
SAMPLE_BYTES = 48 + 75 * 4         # a training sample in memory


def exchange_seconds(ranks: int) -> float:
    """The decoder's gradients summed by recursive doubling (log2 N exchanges of
    the whole vector: the fixed tree that makes the bake's bits independent of
    N) + allgather of the latent rows."""
    if ranks == 1:
        return 0.0
    nodes = max(1, math.ceil(ranks / CORES_PER_NODE))
    lat, bw = (LATENCY, BANDWIDTH) if nodes > 1 else (SHARED_LATENCY, SHARED_BANDWIDTH)
    allreduce = math.log2(ranks) * (lat + DECODER_BYTES / bw)
    rows = 3 * BATCH * ROW_BYTES  # every rank receives every rank's rows
    allgather = math.log2(ranks) * lat + (ranks - 1) / ranks * rows / bw
    return allreduce + allgather


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--vertices", type=float, default=10e6)
    ap.add_argument("--cores", default="8,64,512")
    ap.add_argument("--latent-updates", choices=["all", "touched"], default="all")
    a = ap.parse_args()
    points = a.vertices * POINTS_PER_VERTEX
    latent_floats = a.vertices * 7
    per_float = SECONDS_PER_LATENT_FLOAT if a.latent_updates == "all" else SECONDS_PER_LATENT_FLOAT_TOUCHED
    adam = latent_floats * per_float
    print(f"level: {a.vertices:.3g} vertices, {points:.3g} points, {points * SAMPLES_PER_POINT:.3g} samples; "
          f"{STEPS} steps of {BATCH}; --latent-updates {a.latent_updates}")
    print("| cores | sampling | compute / step | latent table / step | exchange / step | training | total | "
          "memory / rank (GiB) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for cores in (int(c) for c in a.cores.split(",")):
        sampling = points * SECONDS_PER_POINT / cores
        compute = BATCH * SECONDS_PER_SAMPLE / cores
        exchange = exchange_seconds(cores)
        training = STEPS * (compute + adam + exchange)
        memory = points * SAMPLES_PER_POINT * SAMPLE_BYTES / cores + latent_floats * 4 * 3
        print(f"| {cores} | {sampling / 60:.1f} min | {compute * 1e3:.2f} ms | {adam * 1e3:.1f} ms | "
              f"{exchange * 1e3:.3f} ms | {training / 60:.1f} min | {(sampling + training) / 60:.1f} min | "
              f"{memory / 2**30:.1f} |")


if __name__ == "__main__":
    main()
