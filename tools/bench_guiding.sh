#!/usr/bin/env bash
# Path guiding against BSDF sampling alone (issue 16, docs/guiding.md): for each scene, a converged
# unguided reference (rendered once, kept in DIR), then REPEATS interleaved pairs (unguided, guided;
# seeds 1, 2, ...) at the same spp, each timed (wall clock of the whole `nusselt render`, set-up,
# training and pipeline compilation included) and compared with the reference (relMSE from
# `nusselt diff`). Prints per run and the medians: relMSE, seconds, relMSE x seconds (lower is
# better: the error at equal time, for an error falling as 1 / time), and the ratio unguided /
# guided of the medians' products (> 1: guiding wins).
#
#   tools/bench_guiding.sh [DIR] [NUSSELT]
# Environment: SIZE (default 128), SPP (64), REF_SPP (4096), REPEATS (3), DEPTH (8),
#   SCENES (default: scenes/cornell/cornell-indirect.glb, scenes/tests/guiding_gap.gltf and the
#   default Cornell box, "default"),
#   GUIDE_ARGS (extra options of the guided renders, e.g. "--guide-spatial 1000").
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-/tmp/nusselt-bench-guiding}
bin=${2:-build/nusselt}
[ -x "$bin" ] || { echo "no binary $bin: build first" >&2; exit 2; }
size=${SIZE:-128}
spp=${SPP:-64}
refSpp=${REF_SPP:-4096}
repeats=${REPEATS:-3}
depth=${DEPTH:-8}
scenes=${SCENES:-"scenes/cornell/cornell-indirect.glb scenes/tests/guiding_gap.gltf default"}
mkdir -p "$dir"
# shellcheck source=tools/bench_lib.sh
source tools/bench_lib.sh
common="--width $size --height $size --max-depth $depth -q --checkpoint 0"


echo "bench_guiding: ${size}x${size}, $spp spp per run, reference $refSpp spp (unguided), max depth $depth, $repeats repeats, guided with: --guiding on ${GUIDE_ARGS:-}"
echo "device: $("$bin" devices | head -1)"
for scene in $scenes; do
  name=$(scene_name "$scene")
  sceneArg=$(scene_arg "$scene")
  ref="$dir/$name-ref-$size-$refSpp-$depth.exr"
  # shellcheck disable=SC2086
  bench_reference "$bin" "$scene" "$ref" "$refSpp" $common
  : > "$dir/$name.off"
  : > "$dir/$name.on"
  for ((r = 1; r <= repeats; r++)); do
    for mode in off on; do
      out="$dir/$name-$mode-$r.exr"
      t0=$(date +%s.%N)
      # shellcheck disable=SC2086
      extra=""
      [ "$mode" = on ] && extra=${GUIDE_ARGS:-}
      "$bin" render $sceneArg $common --spp "$spp" --seed "$r" --guiding "$mode" $extra -o "$out"
      t1=$(date +%s.%N)
      sec=$(echo "$t1 - $t0" | bc -l)
      rel=$("$bin" diff "$out" "$ref" | awk '{print $2}')
      prod=$(calc "$rel * $sec")
      printf "%-20s guiding %-3s seed %d: relMSE %.5g  %.2f s  relMSE x s %.5g\n" "$name" "$mode" "$r" "$rel" "$sec" "$prod"
      echo "$rel $sec $prod" >> "$dir/$name.$mode"
    done
  done
  for mode in off on; do
    mr=$(awk '{print $1}' "$dir/$name.$mode" | median)
    ms=$(awk '{print $2}' "$dir/$name.$mode" | median)
    mp=$(awk '{print $3}' "$dir/$name.$mode" | median)
    printf "%-20s guiding %-3s median: relMSE %.5g  %.2f s  relMSE x s %.5g\n" "$name" "$mode" "$mr" "$ms" "$mp"
    eval "p_$mode=$mp"
    eval "r_$mode=$mr"
  done
  printf "%-20s unguided / guided: relMSE %.3fx, relMSE x time %.3fx (> 1: guiding wins)\n" "$name" \
    "$(calc "$r_off / $r_on")" "$(calc "$p_off / $p_on")"
done
