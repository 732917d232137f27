#!/usr/bin/env bash
# Path guiding against BSDF sampling alone (issue 16, docs/guiding.md): for each scene, a converged
# unguided reference (rendered once, kept in DIR), then REPEATS interleaved rounds (unguided, then
# each guided variant; seeds 1, 2, ...) at the same spp, each timed (wall clock of the whole `nusselt render`, set-up,
# training and pipeline compilation included) and compared with the reference (relMSE from
# `nusselt diff`). Prints per run and the medians: relMSE, seconds, relMSE x seconds (lower is
# better: the error at equal time, for an error falling as 1 / time), and per variant the ratio
# unguided / guided of the medians' products (> 1: guiding wins).
#
#   tools/bench_guiding.sh [DIR] [NUSSELT]
# Environment: SIZE (default 128), SPP (64), REF_SPP (4096), REPEATS (3), DEPTH (8),
#   SCENES (default: scenes/cornell/cornell-indirect.glb, scenes/tests/guiding_gap.gltf and the
#   default Cornell box, "default"),
#   GUIDE_ARGS (extra options of the guided renders, e.g. "--guide-spatial 1000"),
#   VARIANTS (guided variants' own options, separated by "|", each added to GUIDE_ARGS; default
#   one variant without options, e.g. "--guide-alpha auto|--guide-alpha 0.5").
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


IFS='|' read -r -a variants <<< "${VARIANTS:-}"
[ ${#variants[@]} -eq 0 ] && variants=("")
modes=(off)
for ((v = 0; v < ${#variants[@]}; v++)); do modes+=("on$v"); done
echo "bench_guiding: ${size}x${size}, $spp spp per run, reference $refSpp spp (unguided), max depth $depth, $repeats repeats, guided with: --guiding on ${GUIDE_ARGS:-}"
for ((v = 0; v < ${#variants[@]}; v++)); do echo "  variant on$v: ${variants[$v]}"; done
echo "load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "device: $("$bin" devices | head -1)"
for scene in $scenes; do
  name=$(scene_name "$scene")
  sceneArg=$(scene_arg "$scene")
  ref="$dir/$name-ref-$size-$refSpp-$depth.exr"
  # shellcheck disable=SC2086
  bench_reference "$bin" "$scene" "$ref" "$refSpp" $common
  for mode in "${modes[@]}"; do : > "$dir/$name.$mode"; done
  for ((r = 1; r <= repeats; r++)); do
    for mode in "${modes[@]}"; do
      out="$dir/$name-$mode-$r.exr"
      t0=$(date +%s.%N)
      guiding=off
      extra=""
      if [ "$mode" != off ]; then
        guiding=on
        extra="${GUIDE_ARGS:-} ${variants[${mode#on}]}"
      fi
      # shellcheck disable=SC2086
      "$bin" render $sceneArg $common --spp "$spp" --seed "$r" --guiding "$guiding" $extra -o "$out"
      t1=$(date +%s.%N)
      sec=$(echo "$t1 - $t0" | bc -l)
      rel=$("$bin" diff "$out" "$ref" | awk '{print $2}')
      prod=$(calc "$rel * $sec")
      printf "%-20s guiding %-3s seed %d: relMSE %.5g  %.2f s  relMSE x s %.5g  (load %s)\n" "$name" "$mode" "$r" "$rel" \
        "$sec" "$prod" "$(cut -d' ' -f1 /proc/loadavg)"
      echo "$rel $sec $prod" >> "$dir/$name.$mode"
    done
  done
  for mode in "${modes[@]}"; do
    mr=$(awk '{print $1}' "$dir/$name.$mode" | median)
    ms=$(awk '{print $2}' "$dir/$name.$mode" | median)
    mp=$(awk '{print $3}' "$dir/$name.$mode" | median)
    printf "%-20s guiding %-3s median: relMSE %.5g  %.2f s  relMSE x s %.5g\n" "$name" "$mode" "$mr" "$ms" "$mp"
    eval "p_$mode=$mp"
    eval "r_$mode=$mr"
  done
  for mode in "${modes[@]:1}"; do
    rOn=r_$mode
    pOn=p_$mode
    printf "%-20s unguided / guided %s: relMSE %.3fx, relMSE x time %.3fx (> 1: guiding wins)\n" "$name" "$mode" \
      "$(calc "$r_off / ${!rOn}")" "$(calc "$p_off / ${!pOn}")"
  done
done
