#!/usr/bin/env bash
# Runs tests on Debian 12's own lavapipe (Mesa 22.3) beside the Mesa 25 that tools/bootstrap.sh
# installs: nusselt must still run there (slower, no ray queries; issue 21). The bookworm package
# mesa-vulkan-drivers is downloaded (not installed) and unpacked into ~/.cache/nusselt/mesa-22.3;
# the Vulkan loader is pointed at its lavapipe only (VK_ICD_FILENAMES), so nothing on the system
# changes.
#
#   tools/test_mesa22.sh [CTEST ARGS...]   default: the GPU-labelled tests (-L gpu)
#   tools/test_mesa22.sh -L render -R Furnace
#
# Needs build/ (tools/bootstrap.sh) and apt sources for bookworm. Prints the driver it ran on.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/nusselt ] || { echo "build/nusselt is missing: run tools/bootstrap.sh first" >&2; exit 1; }
cache=${XDG_CACHE_HOME:-$HOME/.cache}/nusselt/mesa-22.3
lib=$cache/root/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so
if [ ! -f "$lib" ]; then
  mkdir -p "$cache"
  # The bookworm (not backports) version: the highest 22.3 one apt knows.
  version=$(apt-cache madison mesa-vulkan-drivers | awk '$3 ~ /^22\.3/ {print $3; exit}')
  [ -n "$version" ] || { echo "no Mesa 22.3 mesa-vulkan-drivers in the apt sources (bookworm needed)" >&2; exit 1; }
  (cd "$cache" && apt-get download "mesa-vulkan-drivers=$version" >/dev/null 2>&1 ||
     { echo "apt-get download mesa-vulkan-drivers=$version failed" >&2; exit 1; })
  dpkg -x "$cache"/mesa-vulkan-drivers_*.deb "$cache/root"
  rm -f "$cache"/mesa-vulkan-drivers_*.deb
fi
[ -f "$lib" ] || { echo "$lib missing after unpacking" >&2; exit 1; }
missing=$(ldd "$lib" | grep "not found" || true)
[ -z "$missing" ] || { echo "Mesa 22.3's lavapipe lacks libraries: $missing" >&2; exit 1; }
cat > "$cache/lvp_icd.json" <<EOF
{"file_format_version": "1.0.0", "ICD": {"library_path": "$lib", "api_version": "1.1.230"}}
EOF
export VK_ICD_FILENAMES=$cache/lvp_icd.json VK_DRIVER_FILES=$cache/lvp_icd.json
build/nusselt devices
driver=$(build/nusselt devices | grep -o "Mesa [0-9.]*" | head -1)
[[ "$driver" == "Mesa 22.3"* ]] || { echo "expected Mesa 22.3, the loader found: $driver" >&2; exit 1; }
[ $# -gt 0 ] || set -- -L gpu
ctest --test-dir build --output-on-failure "$@"
