#!/usr/bin/env bash
# Installs every Debian package the project builds or tests with. Idempotent:
# it only calls apt-get when something is missing. Works as root, or through
# sudo where there is one. Debian 12 (bookworm).
set -euo pipefail

# glslang-tools: glslang-dev's CMake config names /usr/bin/glslangValidator, and
# with --no-install-recommends nothing else brings it, so find_package fails.
packages=(
  build-essential cmake ninja-build pkg-config git
  libtbb-dev libglm-dev libstb-dev libopenexr-dev libtinygltf-dev nlohmann-json3-dev libembree-dev libdnnl-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  liblua5.4-dev libglfw3-dev libimgui-dev libgl-dev libgl1-mesa-dri
  libvulkan-dev glslang-dev glslang-tools spirv-tools mesa-vulkan-drivers vulkan-validationlayers
  xvfb xauth ffmpeg
)
# --fuzz: also the compiler of the `fuzz` preset (clang 14 with libFuzzer and
# its sanitizer runtimes; tests/fuzz/README.md). The test suite does not need it.
if [[ "${1:-}" == "--fuzz" ]]; then
  packages+=(clang-14 libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    echo "setup-deps: need root or sudo to install: ${missing[*]}" >&2
    exit 1
  fi
fi

echo "setup-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -q
"${as_root[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
