#!/usr/bin/env bash
# Metropolis (--integrator mlt, docs/mlt.md) against the path tracer at equal time: for each scene,
# a converged path-traced reference (rendered once, kept in DIR), then REPEATS interleaved pairs
# (path, mlt; seeds 1, 2, ...), each with the same time budget (--time), compared with the
# reference (relMSE from `nusselt diff`). Prints per run and the medians: relMSE, the render's
# sampling seconds (header nusselt/renderSeconds; a budget ends at a pass boundary, so the times
# differ a little), paths per second, relMSE x seconds (lower is better: the error at equal time
# for an error falling as 1 / time), and the ratio path / mlt of the medians' products (> 1: mlt
# wins). The reference's own noise adds the same amount to both relMSEs (it is a few per cent of
# them at the defaults: REF_SPP is ~10x what a run reaches).
#
#   tools/bench_mlt.sh [DIR] [NUSSELT]
# Environment: SIZE (default 128), TIME (10 s), REF_SPP (2048), REPEATS (3), DEPTH (8),
#   SCENES (default: the default Cornell box "default" and scenes/cornell/cornell-glass.glb),
#   MLT_ARGS (extra options of the mlt renders, e.g. "--mlt-chains 32768").
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-/tmp/nusselt-bench-mlt}
bin=${2:-build/nusselt}
[ -x "$bin" ] || { echo "no binary $bin: build first" >&2; exit 2; }
size=${SIZE:-128}
budget=${TIME:-10}
refSpp=${REF_SPP:-2048}
repeats=${REPEATS:-3}
depth=${DEPTH:-8}
scenes=${SCENES:-"default scenes/cornell/cornell-glass.glb"}
mkdir -p "$dir"
common="--width $size --height $size --max-depth $depth -q --checkpoint 0"

# shellcheck source=tools/bench_lib.sh
source tools/bench_lib.sh
attr() { "$bin" info "$1" | sed -n "s/^  nusselt\/$2: //p" | head -1; }

echo "bench_mlt: ${size}x${size}, --time $budget per run, reference $refSpp spp (path), max depth $depth, $repeats repeats, mlt with: ${MLT_ARGS:-(defaults)}"
echo "device: $("$bin" devices | head -1)"
for scene in $scenes; do
  name=$(scene_name "$scene")
  sceneArg=$(scene_arg "$scene")
  ref="$dir/$name-ref-$size-$refSpp-$depth.exr"
  # shellcheck disable=SC2086
  bench_reference "$bin" "$scene" "$ref" "$refSpp" $common
  : > "$dir/$name.path"
  : > "$dir/$name.mlt"
  for ((r = 1; r <= repeats; r++)); do
    for mode in path mlt; do
      out="$dir/$name-$mode-$r.exr"
      extra=""
      [ "$mode" = mlt ] && extra=${MLT_ARGS:-}
      # shellcheck disable=SC2086
      "$bin" render $sceneArg $common --time "$budget" --seed "$r" --integrator "$mode" $extra -o "$out"
      sec=$(attr "$out" renderSeconds)
      spp=$(attr "$out" spp)
      paths=$(echo "$spp * $([ "$mode" = mlt ] && attr "$out" mltChains || echo "$size * $size")" | bc -l)
      rel=$("$bin" diff "$out" "$ref" | awk '{print $2}')
      prod=$(calc "$rel * $sec")
      rate=$(echo "$paths / $sec / 1000000" | bc -l)
      printf "%-14s %-4s seed %d: relMSE %.5g  %.2f s  %.3f Mpaths/s  relMSE x s %.5g\n" "$name" "$mode" "$r" "$rel" "$sec" "$rate" "$prod"
      echo "$rel $sec $prod $rate" >> "$dir/$name.$mode"
    done
  done
  for mode in path mlt; do
    rel=$(awk '{print $1}' "$dir/$name.$mode" | median)
    sec=$(awk '{print $2}' "$dir/$name.$mode" | median)
    prod=$(awk '{print $3}' "$dir/$name.$mode" | median)
    rate=$(awk '{print $4}' "$dir/$name.$mode" | median)
    printf "%-14s %-4s median: relMSE %.5g  %.2f s  %.3f Mpaths/s (mlt: mutations, bootstrap excluded)  relMSE x s %.5g\n" \
      "$name" "$mode" "$rel" "$sec" "$rate" "$prod"
    echo "$prod" > "$dir/$name.$mode.median"
  done
  printf "%-14s path / mlt (relMSE x s): %.3f\n" "$name" "$(calc "$(cat "$dir/$name.path.median") / $(cat "$dir/$name.mlt.median")")"
done
