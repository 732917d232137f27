#!/usr/bin/env bash
# VEGAS (--integrator vegas, docs/vegas.md) against the path tracer at equal time: for each scene,
# a converged path-traced reference (rendered once, kept in DIR), then REPEATS interleaved pairs
# (path, vegas; seeds 1, 2, ...), each with the same time budget (--time), compared with the
# reference (relMSE from `nusselt diff`). Prints per run and the medians: relMSE, the render's
# sampling seconds (header nusselt/renderSeconds; a budget ends at a pass boundary, so the times
# differ a little), paths per second, relMSE x seconds (lower is better: the error at equal time
# for an error falling as 1 / time), relMSE x spp (the error per path, throughput aside), and the
# ratio path / vegas of the medians' relMSE x s (> 1: vegas wins). The reference's own noise adds
# the same amount to both relMSEs.
#
#   tools/bench_vegas.sh [DIR] [NUSSELT]
# Environment: SIZE (default 128), TIME (10 s), REF_SPP (2048; the fast test scenes reach ~3000
#   spp in 10 s: give them REF_SPP=32768), REPEATS (3), DEPTH (8),
#   SCENES (default: the default Cornell box "default", scenes/tests/punctual.gltf and
#   scenes/tests/mis.gltf), VEGAS_ARGS (extra options of the vegas renders, e.g. "--vegas-bins 16").
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-/tmp/nusselt-bench-vegas}
bin=${2:-build/nusselt}
[ -x "$bin" ] || { echo "no binary $bin: build first" >&2; exit 2; }
size=${SIZE:-128}
budget=${TIME:-10}
refSpp=${REF_SPP:-2048}
repeats=${REPEATS:-3}
depth=${DEPTH:-8}
scenes=${SCENES:-"default scenes/tests/punctual.gltf scenes/tests/mis.gltf"}
mkdir -p "$dir"
common="--width $size --height $size --max-depth $depth -q --checkpoint 0"

# shellcheck source=tools/bench_lib.sh
source tools/bench_lib.sh
attr() { "$bin" info "$1" | sed -n "s/^  nusselt\/$2: //p" | head -1; }

echo "bench_vegas: ${size}x${size}, --time $budget per run, reference $refSpp spp (path), max depth $depth, $repeats repeats, vegas with: ${VEGAS_ARGS:-(defaults)}"
echo "device: $("$bin" devices | head -1)"
for scene in $scenes; do
  name=$(scene_name "$scene")
  sceneArg=$(scene_arg "$scene")
  ref="$dir/$name-ref-$size-$refSpp-$depth.exr"
  # shellcheck disable=SC2086
  bench_reference "$bin" "$scene" "$ref" "$refSpp" $common
  : > "$dir/$name.path"
  : > "$dir/$name.vegas"
  for ((r = 1; r <= repeats; r++)); do
    for mode in path vegas; do
      out="$dir/$name-$mode-$r.exr"
      extra=""
      [ "$mode" = vegas ] && extra=${VEGAS_ARGS:-}
      # shellcheck disable=SC2086
      "$bin" render $sceneArg $common --time "$budget" --seed "$r" --integrator "$mode" $extra -o "$out"
      sec=$(attr "$out" renderSeconds)
      spp=$(attr "$out" spp)
      rel=$("$bin" diff "$out" "$ref" | awk '{print $2}')
      prod=$(calc "$rel * $sec")
      rate=$(calc "$spp * $size * $size / $sec / 1000000")
      perPath=$(calc "$rel * $spp")
      printf "%-14s %-5s seed %d: relMSE %.5g  %.2f s  %d spp  %.3f Mpaths/s  relMSE x s %.5g  relMSE x spp %.4g\n" \
        "$name" "$mode" "$r" "$rel" "$sec" "$spp" "$rate" "$prod" "$perPath"
      echo "$rel $sec $prod $rate $perPath" >> "$dir/$name.$mode"
    done
  done
  for mode in path vegas; do
    rel=$(awk '{print $1}' "$dir/$name.$mode" | median)
    sec=$(awk '{print $2}' "$dir/$name.$mode" | median)
    prod=$(awk '{print $3}' "$dir/$name.$mode" | median)
    rate=$(awk '{print $4}' "$dir/$name.$mode" | median)
    perPath=$(awk '{print $5}' "$dir/$name.$mode" | median)
    printf "%-14s %-5s median: relMSE %.5g  %.2f s  %.3f Mpaths/s  relMSE x s %.5g  relMSE x spp %.4g\n" "$name" "$mode" "$rel" \
      "$sec" "$rate" "$prod" "$perPath"
    echo "$prod" > "$dir/$name.$mode.median"
  done
  printf "%-14s path / vegas (relMSE x s): %.3f\n" "$name" \
    "$(calc "$(cat "$dir/$name.path.median") / $(cat "$dir/$name.vegas.median")")"
done
