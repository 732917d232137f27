#!/usr/bin/env bash
# Compares two EXR images for users: relMSE (mean over pixels and channels of
# (x - ref)^2 / (ref^2 + 0.01)), MSE, the means of both and the largest absolute difference.
# It is `nusselt diff` (src/io/image.cpp, compareImages), which the benchmarks use too; the second
# image is the reference. Sizes must match.
# Usage: tools/compare_exr.sh IMAGE.exr REFERENCE.exr [path/to/nusselt]
set -euo pipefail
if [ $# -lt 2 ] || [ $# -gt 3 ]; then
  echo "usage: $0 IMAGE.exr REFERENCE.exr [path/to/nusselt]" >&2
  exit 2
fi
here=$(cd "$(dirname "$0")/.." && pwd)
nusselt=${3:-${NUSSELT:-$here/build/nusselt}}
[ -x "$nusselt" ] || { echo "error: $nusselt not found (build first, or pass its path)" >&2; exit 2; }
exec "$nusselt" diff "$1" "$2"
