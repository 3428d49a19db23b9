#!/usr/bin/env bash
# Packs what a GPU run through the `device` tool needs into .devpack/ (which
# .git/info/exclude must ignore; the tool's `carry` takes it): the stripped
# transgi binary, gpu_bench and gpu_tests (the kernels against their CPU
# oracles, on the real GPU), every shared library they load except glibc's
# and the Vulkan loader (the loader comes from .gl, see
# /work/.library/device/README.md), and Bitterli's Living Room with its model
# when they are there (the model: \$BITTERLI_MODEL, else out/bitterli/bitterli.tgm). The device machine's image is not Debian, and nothing
# can be installed there. Usage: scripts/gpu_pack.sh [build dir]
set -euo pipefail
build=${1:-build/release}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/lib" "$stage/bitterli" .devpack
for bin in "$build/modules/transgi/transgi" "$build/benchmarks/gpu_bench" "$build/tests/gpu_tests"; do
  [ -x "$bin" ] || { echo "gpu_pack: $bin is missing; build first (cmake --build --preset release)" >&2; exit 1; }
  cp "$bin" "$stage/" && strip "$stage/$(basename "$bin")"
  for lib in $(ldd "$bin" | awk '$3 ~ /^\// {print $3}'); do
    case "$(basename "$lib")" in
      libc.so*|libm.so*|libvulkan.so*) ;;  # the machine's own glibc; the loader from .gl
      *) cp -L "$lib" "$stage/lib/" ;;
    esac
  done
done
scene=../shared/scenes/bitterli-living-room
model=${BITTERLI_MODEL:-out/bitterli/bitterli.tgm}
if [ -f "$scene/scene.gltf" ] && [ -f "$model" ]; then
  cp -r "$scene/scene.gltf" "$scene/scene.bin" "$scene/textures" "$scene/Sky_19.exr" "$stage/bitterli/"
  cp "$model" "$stage/bitterli/bitterli.tgm"
else
  echo "gpu_pack: no Bitterli room or $model; packing without it" >&2
fi
tar -cf - -C "$stage" . | xz -T2 -6 > .devpack/pk.tar.xz.tmp
mv .devpack/pk.tar.xz.tmp .devpack/pk.tar.xz
echo "gpu_pack: .devpack/pk.tar.xz, $(du -h .devpack/pk.tar.xz | cut -f1) (the tool carries 64 MiB with the tree)"
