#!/usr/bin/env bash
# Regenerates the reference images of the render tests (tests/data/refs/). Each reference is a
# high-spp render with its per-pixel variance (--variance), made with seeds the tests do not use.
# Usage: tools/make_references.sh [path/to/nusselt]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
nusselt=${1:-$here/build/nusselt}
out=$here/tests/data/refs
mkdir -p "$out"
"$nusselt" render -o "$out/cornell-box.exr" --width 64 --height 64 --spp 8192 --seed 1000 --max-depth 8 --variance
