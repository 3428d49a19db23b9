#!/usr/bin/env bash
# Installs every Debian package the project builds or tests with. Idempotent:
# it only calls apt-get when something is missing. Works as root, or through
# sudo where there is one. Debian 12 (bookworm).
set -euo pipefail

# glslang-tools: glslang-dev's CMake config names /usr/bin/glslangValidator, and
# with --no-install-recommends nothing else brings it, so find_package fails.
# openmpi-*: the bake on many processes (mpirun -n N transgi bake, docs/bake.md);
# the build turns it on where MPI is found, and the suite then runs a 2-rank bake.
# mesa-vulkan-drivers (lavapipe) comes from bookworm-backports (Mesa 25), below:
# bookworm's own 22.3 has no VK_KHR_ray_query, whose path the GPU tests run.
packages=(
  build-essential cmake ninja-build pkg-config git
  libtbb-dev libglm-dev libstb-dev libopenexr-dev libtinygltf-dev nlohmann-json3-dev libembree-dev libdnnl-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  liblua5.4-dev libglfw3-dev libimgui-dev libgl-dev libgl1-mesa-dri
  libvulkan-dev glslang-dev glslang-tools spirv-tools vulkan-validationlayers
  xvfb xauth ffmpeg help2man
  openmpi-bin libopenmpi-dev
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

# Debian 12 ships Mesa 22.3, whose lavapipe has no ray queries; its backports
# carry Mesa 25 (VK_KHR_ray_query, VK_KHR_acceleration_structure). Later
# Debian releases have a Mesa new enough in their own archive.
mesa_minimum=25
codename=$(. /etc/os-release 2>/dev/null && echo "${VERSION_CODENAME:-}")
mesa_installed=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
need_mesa=0
if [ -z "$mesa_installed" ] || dpkg --compare-versions "$mesa_installed" lt "$mesa_minimum"; then
  need_mesa=1
fi

if [ ${#missing[@]} -eq 0 ] && [ $need_mesa -eq 0 ]; then
  echo "setup-deps: all ${#packages[@]} packages already installed, and mesa-vulkan-drivers $mesa_installed"
  exit 0
fi

as_root=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then
    as_root=(sudo)
  else
    echo "setup-deps: need root or sudo to install: ${missing[*]}$([ $need_mesa -eq 1 ] && echo " mesa-vulkan-drivers>=$mesa_minimum")" >&2
    exit 1
  fi
fi

export DEBIAN_FRONTEND=noninteractive
mesa_release=()
if [ $need_mesa -eq 1 ] && [ "$codename" = "bookworm" ]; then
  if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    echo "setup-deps: adding Debian's bookworm-backports (for mesa-vulkan-drivers >= $mesa_minimum)"
    printf 'Types: deb\nURIs: http://deb.debian.org/debian\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' |
      "${as_root[@]}" tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null
  fi
  mesa_release=(-t bookworm-backports)
fi
"${as_root[@]}" apt-get update -q
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup-deps: installing ${missing[*]}"
  "${as_root[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
if [ $need_mesa -eq 1 ]; then
  echo "setup-deps: installing mesa-vulkan-drivers ${mesa_release[*]} (was: ${mesa_installed:-none})"
  "${as_root[@]}" apt-get install -y -q --no-install-recommends "${mesa_release[@]}" mesa-vulkan-drivers
fi
