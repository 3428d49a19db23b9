#!/usr/bin/env bash
# The device check, in one call of the `device` tool (docs/gpu.md):
# `scripts/gpu_pack.sh` here, then `bash scripts/gpu_run.sh` there with
# carry [".gl", ".devpack"]. The GPU tests on the real GPU, then 1080p frames of the level
# and Bitterli's Living Room, the Vulkan and CPU backends alternating (and the
# level with the camera's rays traced instead of rasterised); every
# output in $OUT/results.tgz (the tool brings back at most 8 files). The
# tests' content paths are compiled in as /work/main/...: a link makes them resolve.
set -u
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig
mkdir -p /work && ln -sfn "$PWD" /work/main
mkdir -p /tmp/pk && tar -xJf .devpack/pk.tar.xz -C /tmp/pk
export LD_LIBRARY_PATH=/tmp/pk/lib VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
nvidia-smi -L; nproc; grep -m1 "model name" /proc/cpuinfo; nvidia-smi --query-gpu=clocks.sm,clocks.max.sm --format=csv
cd /work/main
R=$OUT/r; mkdir -p $R
( nvidia-smi dmon -s uc -d 1 > $R/dmon.txt 2>&1 & echo $! > /tmp/dmon.pid )
echo "== gpu_tests"; t0=$(date +%s)
timeout 200 /tmp/pk/gpu_tests > $R/gpu_tests.log 2>&1; echo "gpu_tests rc $? in $(( $(date +%s) - t0 )) s"
grep -E "^\[  (FAILED|PASSED|SKIPPED) |rays:|device:" $R/gpu_tests.log | sort | uniq -c | head -40
T=/tmp/pk/transgi
L="--scene content/levels/living_room/scene.gltf --model content/levels/living_room/transgi.tgm --width 1920 --height 1080 --frames 20 --warmup 24"
B="--scene /tmp/pk/bitterli/scene.gltf --model /tmp/pk/bitterli/bitterli.tgm --width 1920 --height 1080 --frames 20 --warmup 24"
run() { name=$1; shift; echo "== $name: $*"; t0=$(date +%s); timeout 120 $T bench-frame "$@" --csv $R/$name.csv > $R/$name.txt 2>&1; echo "rc $? in $(( $(date +%s) - t0 )) s"; grep -vE "^\s*(bench-frame|frame) .*ETA|\[#" $R/$name.txt | tail -25; }
run level_vk $L --backend vulkan
run level_cpu $L --backend cpu
run level_vk_di $L --backend vulkan --device-inference on
run level_vk2 $L --backend vulkan
ENGINE_GPU_RASTER_VISIBILITY=off run level_vk_camera_rays $L --backend vulkan
echo "== gpu_bench: primary visibility, rasterised against traced"
timeout 90 /tmp/pk/gpu_bench --benchmark_filter=PrimaryVisibility > $R/gpu_bench_visibility.txt 2>&1; tail -6 $R/gpu_bench_visibility.txt
run bitterli_vk $B --backend vulkan
run bitterli_cpu $B --backend cpu
ddgi() { name=$1; shift; echo "== $name: $*"; t0=$(date +%s); timeout 90 $T render "$@" --method ddgi --width 1920 --height 1080 --frames 24 --out $R/$name.exr > $R/$name.txt 2>&1; echo "rc $? in $(( $(date +%s) - t0 )) s"; grep -iE "stage|ms" $R/$name.txt | tail -8; rm -f $R/$name.exr; }
ddgi level_ddgi_vk --scene content/levels/living_room/scene.gltf --probe-volume scene --backend vulkan
ddgi level_ddgi_cpu --scene content/levels/living_room/scene.gltf --probe-volume scene --backend cpu
kill $(cat /tmp/dmon.pid) 2>/dev/null
tar -czf $OUT/results.tgz -C $OUT r && rm -rf $R
