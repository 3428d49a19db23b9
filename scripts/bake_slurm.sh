#!/usr/bin/env bash
# Bakes a level on a Slurm cluster: `transgi bake` as one MPI rank per node,
# each rank's threads on that node's cores (docs/bake.md, "Baking on many
# machines").
#
#   sbatch --nodes=8 scripts/bake_slurm.sh LEVEL.gltf OUT.tgm [transgi bake options]
#
# OUT's folder must be on a file system every node sees: each rank caches its
# dataset shard there, rank 0 writes the checkpoints and the model. The bake
# always runs with --resume, so a job that was requeued, or cut off by its
# time limit and submitted again, goes on from its last checkpoint and cached
# shards instead of starting over (with nothing to resume from, --resume
# starts a new bake). Resume with the same number of nodes: the shards are
# cached per rank count.
#
# Environment: TRANSGI, the transgi binary (default: `transgi` on PATH);
# TRANSGI_LAUNCH, the launcher (default: srun; "srun --mpi=pmix" where the
# site's MpiDefault does not start MPI jobs, or "mpirun" inside the allocation).
#SBATCH --job-name=transgi-bake
#SBATCH --nodes=4
#SBATCH --ntasks-per-node=1
#SBATCH --cpus-per-task=32
#SBATCH --time=04:00:00
#SBATCH --requeue
#SBATCH --open-mode=append
#SBATCH --output=transgi-bake-%j.log
set -euo pipefail

if [ $# -lt 2 ]; then
  echo "usage: sbatch [--nodes=N] $0 LEVEL.gltf OUT.tgm [transgi bake options]" >&2
  exit 2
fi
scene=$1
out=$2
shift 2
transgi=${TRANSGI:-transgi}
read -r -a launch <<< "${TRANSGI_LAUNCH:-srun}"

mkdir -p "$(dirname "$out")"
echo "transgi-bake: $(date -u +%FT%TZ) job ${SLURM_JOB_ID:-local} on ${SLURM_JOB_NUM_NODES:-1} node(s): $scene -> $out"
# --threads: the cores Slurm gave each rank (0 = every core of the machine).
exec "${launch[@]}" "$transgi" bake --scene "$scene" --out "$out" --threads "${SLURM_CPUS_PER_TASK:-0}" --resume "$@"
