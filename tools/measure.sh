#!/usr/bin/env bash
# Regenerates docs/measurements.md from the benchmarks' own output: the numbers in the docs are
# printed by these commands, never typed. Run on a quiet machine (nothing else using the cores).
# Usage: tools/measure.sh [path/to/nusselt]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
nusselt=${1:-$here/build/nusselt}
out=$here/docs/measurements.md
tmp=$(mktemp)
{
  echo "# Measurements"
  echo
  echo "Produced by \`tools/measure.sh\` on $(date -u +%Y-%m-%d) ($(nproc) cores, $(uname -m))."
  echo "Every block is the verbatim output of the command above it."
  for cmd in "bench render" "bench pipelines" "bench precompute" "bench precompute --preset hard --audit 16"; do
    echo
    echo "## nusselt $cmd"
    echo
    echo '```'
    "$nusselt" $cmd 2>&1
    echo '```'
  done
} >"$tmp"
mv "$tmp" "$out"
echo "wrote $out"
