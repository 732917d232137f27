#!/usr/bin/env bash
# Regenerates docs/measurements.md from the benchmarks' own output: the numbers in the docs are
# printed by these commands, never typed. Run on a quiet machine (nothing else using the cores).
# Usage: tools/measure.sh [--measured] [path/to/nusselt]
#   --measured: only the measured-materials sections (the last ones) are run again and replace
#   theirs in the existing file; the rest of it is kept as it was.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
measuredOnly=0
if [ "${1:-}" = "--measured" ]; then
  measuredOnly=1
  shift
fi
nusselt=$(realpath "${1:-$here/build/nusselt}")  # absolute: the measured commands run in a temporary folder
out=$here/docs/measurements.md
tmp=$(mktemp)
measuredHeading="## Measured materials: nusselt bench precompute"
machine() { echo "$(nproc) cores, $(uname -m), load average $(cut -d' ' -f1-3 /proc/loadavg) at the start"; }
measured() {
  # Measured materials (docs/measured.md): MERL files tabulating analytic models, written by
  # make_merl into a temporary folder (the commands run there, so the output names the files only).
  merl=$(mktemp -d)
  make_merl=$(dirname "$nusselt")/make_merl
  "$make_merl" --model lambert --param rho=0.5 -o "$merl/lambert05.binary" >/dev/null
  "$make_merl" --model torrance_sparrow -o "$merl/torrance_sparrow.binary" >/dev/null
  "$make_merl" --model ward -o "$merl/ward.binary" >/dev/null
  files="--file lambert05.binary --file torrance_sparrow.binary --file ward.binary"
  echo
  echo "$measuredHeading --model merl $files --audit 16"
  echo
  if [ $measuredOnly = 1 ]; then
    echo "This section and the next were produced alone by \`tools/measure.sh --measured\` on $(date -u +%Y-%m-%d) ($(machine))."
    echo
  fi
  echo "The files are written by \`make_merl\` from lambert (rho 0.5), torrance_sparrow and ward (typical sets)."
  echo
  echo '```'
  (cd "$merl" && "$nusselt" bench precompute --model merl $files --audit 16 2>&1)
  echo '```'
  echo
  echo "## Measured materials: albedo of the tabulation against the model (nusselt albedo)"
  echo
  echo '```'
  echo "model             theta   tabulated   analytic   difference"
  for m in torrance_sparrow ward; do
    for t in 0 30 60 85; do
      a=$("$nusselt" albedo --model merl --file "$merl/$m.binary" --theta $t 2>/dev/null)
      b=$("$nusselt" albedo --model $m --theta $t 2>/dev/null)
      awk -v m="$m" -v t="$t" -v a="$a" -v b="$b" 'BEGIN { printf "%-17s %5s %11.6f %10.6f %12.3e\n", m, t, a, b, a - b }'
    done
  done
  echo '```'
  rm -rf "$merl"
}
if [ $measuredOnly = 1 ]; then
  grep -q "^$measuredHeading" "$out" || { echo "measure.sh: no measured section in $out to replace" >&2; exit 1; }
  {
    # Everything before the measured sections, without the blank line that precedes them.
    awk -v h="$measuredHeading" 'index($0, h) == 1 { exit } { print }' "$out" | sed '$ { /^$/d }'
    measured
  } >"$tmp"
  mv "$tmp" "$out"
  echo "wrote the measured sections of $out"
  exit 0
fi
{
  echo "# Measurements"
  echo
  echo "Produced by \`tools/measure.sh\` on $(date -u +%Y-%m-%d) ($(machine)):"
  echo "timings on a shared machine are only comparable with others taken at the same load)."
  echo "Every block is the verbatim output of the command above it."
  for cmd in "bench render" "bench pipelines" "bench precompute" "bench precompute --preset hard --audit 16"; do
    echo
    echo "## nusselt $cmd"
    echo
    echo '```'
    "$nusselt" $cmd 2>&1
    echo '```'
  done
  measured
} >"$tmp"
mv "$tmp" "$out"
echo "wrote $out"
