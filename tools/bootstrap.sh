#!/usr/bin/env bash
# Installs the Debian 12 packages nusselt needs (when missing), then configures and builds it
# into build/. Run as root to install; otherwise it prints the apt-get line to run and stops.
# Usage: tools/bootstrap.sh [extra cmake arguments]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake ninja-build          # compiler and build tools
  libvulkan-dev libvulkan-volk-dev           # Vulkan headers and the volk meta-loader
  mesa-vulkan-drivers                        # lavapipe: a Vulkan device on the CPU
  vulkan-validationlayers                    # the validation layer the tests run under
  glslang-tools                              # GLSL -> SPIR-V at build time
  libglfw3-dev libglm-dev                    # window (preview) and vector maths
  libtinygltf-dev nlohmann-json3-dev libstb-dev  # glTF loading
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
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then
    echo "installing: ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends "${missing[@]}"
  else
    echo "nusselt needs these Debian packages; run as root:" >&2
    echo "  apt-get install ${missing[*]}" >&2
    exit 1
  fi
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build build
echo "built build/nusselt"
