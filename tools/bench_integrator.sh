#!/usr/bin/env bash
# An integrator (--integrator mlt, docs/mlt.md; --integrator vegas, docs/vegas.md) against the
# path tracer at equal time: for each scene, a converged path-traced reference (rendered once, kept
# in DIR), then REPEATS interleaved pairs (path, the integrator; seeds FIRST_SEED, ..., default 1), each with the
# same time budget (--time), compared with the reference (relMSE from `nusselt diff`). Prints per
# run and the medians: relMSE, the render's sampling seconds (header nusselt/renderSeconds; a
# budget ends at a pass boundary, so the times differ a little), paths per second (mlt: mutations,
# the bootstrap excluded), relMSE x seconds (lower is better: the error at equal time for an error
# falling as 1 / time), relMSE x spp (the error per sample, throughput aside; an mlt render's spp
# counts mutations per chain), and the ratio
# path / integrator of the medians' relMSE x s (> 1: the integrator wins); then the means of
# relMSE x s over the seeds with their standard errors and the ratio of the means. The error of a
# Metropolis render is heavy-tailed (a chain that starts at a rare bright path can put half of a
# region's error into a few pixels: docs/mlt.md, "The pool's size"), so the median of a few seeds
# moves a lot between runs; the mean estimates the expected error, which equal-time efficiency
# is about, and its standard error says how far to trust it. The reference's own
# noise adds the same amount to both relMSEs (give REF_SPP ~10x what a run reaches).
# Every run's error map goes beside its image (DIR/NAME-MODE-SEED-error.png, `nusselt diff --map`:
# each pixel grey at its relative error, white at 100 %).
# A scene written SCENE@x0,y0,x1,y1 is also measured in that region of its image (fractions of the
# width and height from the top left, `nusselt diff --region`): its relMSE, relMSE x s and ratio
# are printed for the region as well (e.g. the caustic under the glass sphere).
#
#   tools/bench_integrator.sh mlt|vegas [DIR] [NUSSELT]
# tools/bench_mlt.sh and tools/bench_vegas.sh call it with their integrator's default scenes.
# Environment: SIZE (default 128), TIME (10 s), REF_SPP (2048), REPEATS (3), FIRST_SEED (1: the
#   repeats use seeds FIRST_SEED .. FIRST_SEED + REPEATS - 1), DEPTH (8),
#   SCENES (default: the default Cornell box "default"), ARGS (extra options of the integrator's
#   renders, e.g. "--mlt-chains 32768" or "--vegas-bins 16"), ARGS2, ARGS3 (when set: more variants
#   of the integrator, named INTEGRATOR-2 and INTEGRATOR-3, interleaved with the others in every
#   repeat and each compared with the path tracer, e.g. ARGS="--mlt-pass-spp 0"
#   ARGS2="--mlt-chain-light indirect").
set -euo pipefail
cd "$(dirname "$0")/.."
integrator=${1:?usage: tools/bench_integrator.sh mlt|vegas [DIR] [NUSSELT]}
case $integrator in mlt|vegas) ;; *) echo "unknown integrator '$integrator' (mlt or vegas)" >&2; exit 2 ;; esac
dir=${2:-/tmp/nusselt-bench-$integrator}
bin=${3:-build/nusselt}
[ -x "$bin" ] || { echo "no binary $bin: build first" >&2; exit 2; }
size=${SIZE:-128}
budget=${TIME:-10}
refSpp=${REF_SPP:-2048}
repeats=${REPEATS:-3}
firstSeed=${FIRST_SEED:-1}
depth=${DEPTH:-8}
scenes=${SCENES:-default}
mkdir -p "$dir"
modes=(path "$integrator")
[ -n "${ARGS2:-}" ] && modes+=("$integrator-2")
[ -n "${ARGS3:-}" ] && modes+=("$integrator-3")
# The options of a variant's renders.
variantArgs() { case $1 in path) ;; *-2) echo "${ARGS2:-}" ;; *-3) echo "${ARGS3:-}" ;; *) echo "${ARGS:-}" ;; esac; }
common="--width $size --height $size --max-depth $depth -q --checkpoint 0"

# shellcheck source=tools/bench_lib.sh
source tools/bench_lib.sh
attr() { exr_attr "$bin" "$1" "$2"; }

echo "bench_integrator: $integrator against path, ${size}x${size}, --time $budget per run, reference $refSpp spp (path)," \
     "max depth $depth, $repeats repeats, $integrator with: ${ARGS:-(defaults)}${ARGS2:+; $integrator-2 with: $ARGS2}${ARGS3:+; $integrator-3 with: $ARGS3}"
echo "device: $("$bin" devices | head -1)"
# The mean of column `col` of every mode's runs ($dir/$name.$mode$suffix: relMSE x s) with its
# standard error, then path / mode of the means; `label` follows the mode ("" or "region R ").
print_means() {
  local suffix=$1 col=$2 label=$3 mode m se
  for mode in "${modes[@]}"; do
    read -r m se < <(awk -v c="$col" '{print $c}' "$dir/$name.$mode$suffix" | mean_se)
    printf "%-14s %-5s %smean relMSE x s %.5g +- %.2g (%d seeds)\n" "$name" "$mode" "$label" "$m" "$se" \
      "$(wc -l < "$dir/$name.$mode$suffix")"
    echo "$m" > "$dir/$name.$mode$suffix.mean"
  done
  for mode in "${modes[@]:1}"; do
    printf "%-14s %spath / %s (mean relMSE x s): %.3f\n" "$name" "$label" "$mode" \
      "$(calc "$(cat "$dir/$name.path$suffix.mean") / $(cat "$dir/$name.$mode$suffix.mean")")"
  done
}

for entry in $scenes; do
  scene=${entry%%@*}
  region=""
  [ "$scene" != "$entry" ] && region=${entry#*@}
  name=$(scene_name "$scene")
  sceneArg=$(scene_arg "$scene")
  ref="$dir/$name-ref-$size-$refSpp-$depth.exr"
  # shellcheck disable=SC2086
  bench_reference "$bin" "$scene" "$ref" "$refSpp" $common
  for mode in "${modes[@]}"; do : > "$dir/$name.$mode"; : > "$dir/$name.$mode.region"; done
  for ((r = firstSeed; r < firstSeed + repeats; r++)); do
    for mode in "${modes[@]}"; do
      out="$dir/$name-$mode-$r.exr"
      extra=$(variantArgs "$mode")
      # shellcheck disable=SC2086
      "$bin" render $sceneArg $common --time "$budget" --seed "$r" --integrator "${mode%-[23]}" $extra -o "$out"
      sec=$(attr "$out" renderSeconds)
      spp=$(attr "$out" spp)
      rel=$("$bin" diff "$out" "$ref" --map "${out%.exr}-error.png" | awk '{print $2}')
      # Paths per spp: one per pixel, or chains x steps for Metropolis (mutations; files without
      # mltSteps moved each chain once per iteration).
      steps=$(attr "$out" mltSteps)
      perSpp=$(if [ "${mode%-[23]}" = mlt ]; then echo $(($(attr "$out" mltChains) * ${steps:-1})); else echo $((size * size)); fi)
      prod=$(calc "$rel * $sec")
      rate=$(calc "$spp * $perSpp / $sec / 1000000")
      perPath=$(calc "$rel * $spp")
      printf "%-14s %-5s seed %d: relMSE %.5g  %.2f s  %d spp  %.3f Mpaths/s  relMSE x s %.5g  relMSE x spp %.4g\n" \
        "$name" "$mode" "$r" "$rel" "$sec" "$spp" "$rate" "$prod" "$perPath"
      echo "$rel $sec $prod $rate $perPath" >> "$dir/$name.$mode"
      if [ -n "$region" ]; then
        relR=$("$bin" diff --region "$region" "$out" "$ref" | awk '{print $2}')
        printf "%-14s %-5s seed %d: region %s relMSE %.5g  relMSE x s %.5g\n" "$name" "$mode" "$r" "$region" "$relR" \
          "$(calc "$relR * $sec")"
        echo "$relR $(calc "$relR * $sec")" >> "$dir/$name.$mode.region"
      fi
    done
  done
  for mode in "${modes[@]}"; do
    rel=$(awk '{print $1}' "$dir/$name.$mode" | median)
    sec=$(awk '{print $2}' "$dir/$name.$mode" | median)
    prod=$(awk '{print $3}' "$dir/$name.$mode" | median)
    rate=$(awk '{print $4}' "$dir/$name.$mode" | median)
    perPath=$(awk '{print $5}' "$dir/$name.$mode" | median)
    printf "%-14s %-5s median: relMSE %.5g  %.2f s  %.3f Mpaths/s  relMSE x s %.5g  relMSE x spp %.4g\n" "$name" "$mode" "$rel" \
      "$sec" "$rate" "$prod" "$perPath"
    echo "$prod" > "$dir/$name.$mode.median"
  done
  for mode in "${modes[@]:1}"; do
    printf "%-14s path / %s (relMSE x s): %.3f\n" "$name" "$mode" \
      "$(calc "$(cat "$dir/$name.path.median") / $(cat "$dir/$name.$mode.median")")"
  done
  print_means "" 3 ""
  if [ -n "$region" ]; then
    for mode in "${modes[@]}"; do
      printf "%-14s %-5s region %s median: relMSE %.5g  relMSE x s %.5g\n" "$name" "$mode" "$region" \
        "$(awk '{print $1}' "$dir/$name.$mode.region" | median)" "$(awk '{print $2}' "$dir/$name.$mode.region" | median)"
      awk '{print $2}' "$dir/$name.$mode.region" | median > "$dir/$name.$mode.region.median"
    done
    for mode in "${modes[@]:1}"; do
      printf "%-14s region %s path / %s (relMSE x s): %.3f\n" "$name" "$region" "$mode" \
        "$(calc "$(cat "$dir/$name.path.region.median") / $(cat "$dir/$name.$mode.region.median")")"
    done
    print_means .region 2 "region $region "
  fi
done
