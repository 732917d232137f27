#!/usr/bin/env bash
# Render time against samples per pass: the same render (default scene, max depth 16) with one
# sample per pixel per pass and with the automatic choice, interleaved (1, auto, 1, auto, ...),
# medians of the EXR header's render time; checks that both images are identical.
#   tools/bench_samples_per_pass.sh [REPEATS] [NUSSELT]
# Prints one line per image size. A benchmark, not a test.
set -euo pipefail
repeats=${1:-5}
bin=${2:-$(dirname "$0")/../build/nusselt}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# shellcheck source=tools/bench_lib.sh
source "$(dirname "$0")/bench_lib.sh"
echo "# $("$bin" devices 2>/dev/null | head -1); load average $(cut -d' ' -f1-3 /proc/loadavg); $repeats repeats, interleaved"
printf "%-9s %5s %-14s %-14s %8s %s\n" size spp "1 per pass (s)" "auto (s)" speed-up "images"
for case in "64 256" "256 64"; do
  set -- $case
  size=$1 spp=$2
  : >"$work/t1"; : >"$work/t0"
  for ((i = 0; i < repeats; ++i)); do
    for k in 1 0; do
      "$bin" render --width "$size" --height "$size" --spp "$spp" --max-depth 16 --samples-per-pass $k \
        --checkpoint 0 -o "$work/k$k.exr" 2>"$work/log$k" </dev/null
      exr_attr "$bin" "$work/k$k.exr" renderSeconds >>"$work/t$k"
    done
  done
  auto=$(sed -n 's/.*(\([0-9]*\) per pass).*/\1/p' "$work/log0")
  same=$("$bin" diff "$work/k1.exr" "$work/k0.exr" | awk '{ print ($NF == 0) ? "identical" : "DIFFER" }')
  m1=$(median <"$work/t1"); m0=$(median <"$work/t0")
  printf "%-9s %5s %-14s %-14s %8s %s\n" "${size}x$size" "$spp" "$m1" "$m0 (K=$auto)" \
    "$(awk -v a="$m1" -v b="$m0" 'BEGIN { printf "%.2f", a / b }')" "$same"
done
