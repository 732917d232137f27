#!/usr/bin/env bash
# Installs the Debian 12 packages nusselt needs (when missing), then configures and builds it
# into build/. Run as root to install; otherwise it prints the apt-get lines to run and stops.
# Usage: tools/bootstrap.sh [extra cmake arguments]
#
# The Vulkan driver (lavapipe, in mesa-vulkan-drivers) comes from Debian's bookworm-backports
# suite: Mesa 25 runs our renders 3-4x faster than bookworm's 22.3 and has ray queries. The script
# adds the backports source (deb.debian.org) when it is missing and pulls only that package and
# what it depends on from it; everything else comes from bookworm. NUSSELT_MESA=stable keeps
# bookworm's Mesa 22.3 (nusselt runs on it too, slower).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build          # compiler and build tools
  libvulkan-dev libvulkan-volk-dev           # Vulkan headers and the volk meta-loader
  vulkan-validationlayers                    # the validation layer the tests run under
  glslang-tools                              # GLSL -> SPIR-V at build time
  libglfw3-dev libglm-dev                    # window (preview) and vector maths
  libtinygltf-dev nlohmann-json3-dev libstb-dev  # glTF loading
  libpng-dev libturbojpeg0-dev               # glTF textures: PNG and JPEG decoding
  libdraco-dev libmeshoptimizer-dev          # glTF compressed geometry (Draco, meshopt)
  libopenexr-dev                             # EXR output
  libcli11-dev                               # command-line parsing
  libgtest-dev                               # tests
  xvfb xauth python3                         # preview tests (an X server; PNG checks)
  clang libclang-rt-14-dev llvm              # fuzzers (libFuzzer) and sanitizer runtimes, llvm-symbolizer
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

# lavapipe: Mesa 25 from bookworm-backports unless NUSSELT_MESA=stable.
mesa_version=$(dpkg-query -W -f='${Status} ${Version}' mesa-vulkan-drivers 2>/dev/null |
               sed -n 's/^install ok installed //p' || true)
want_backports=0
if [ "${NUSSELT_MESA:-backports}" = stable ]; then
  [ -n "$mesa_version" ] || missing+=(mesa-vulkan-drivers)
elif [ -z "$mesa_version" ] || dpkg --compare-versions "$mesa_version" lt 25; then
  want_backports=1
fi
backports_list=/etc/apt/sources.list.d/nusselt-bookworm-backports.list
have_backports() { grep -rqsE '^[^#]*bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; }

if [ ${#missing[@]} -gt 0 ] || [ "$want_backports" = 1 ]; then
  if [ "$(id -u)" -ne 0 ]; then
    echo "nusselt needs these Debian packages; run as root:" >&2
    if [ "$want_backports" = 1 ] && ! have_backports; then
      echo "  echo 'deb http://deb.debian.org/debian bookworm-backports main' > $backports_list" >&2
    fi
    [ ${#missing[@]} -gt 0 ] && echo "  apt-get update && apt-get install ${missing[*]}" >&2
    [ "$want_backports" = 1 ] && echo "  apt-get install -t bookworm-backports mesa-vulkan-drivers" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  if [ "$want_backports" = 1 ] && ! have_backports; then
    echo "adding the bookworm-backports apt source ($backports_list)"
    echo 'deb http://deb.debian.org/debian bookworm-backports main' > "$backports_list"
  fi
  apt-get update -qq
  if [ ${#missing[@]} -gt 0 ]; then
    echo "installing: ${missing[*]}"
    apt-get install -y -qq --no-install-recommends "${missing[@]}"
  fi
  if [ "$want_backports" = 1 ]; then
    echo "installing mesa-vulkan-drivers from bookworm-backports (Mesa 25 lavapipe)"
    apt-get install -y -qq --no-install-recommends -t bookworm-backports mesa-vulkan-drivers
  fi
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build build
echo "built build/nusselt"
