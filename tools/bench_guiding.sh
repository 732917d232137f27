#!/usr/bin/env bash
# Path guiding against BSDF sampling alone (issue 16, docs/guiding.md): for each scene, a converged
# unguided reference (rendered once, kept in DIR), then REPEATS interleaved rounds (unguided, then
# each guided variant; seeds 1, 2, ...) at the same spp, each timed (wall clock of the whole `nusselt render`, set-up,
# training and pipeline compilation included) and compared with the reference (relMSE from
# `nusselt diff`). Prints per run and the medians: relMSE, seconds, relMSE x seconds (lower is
# better: the error at equal time, for an error falling as 1 / time), and per variant the ratio
# unguided / guided of the medians' products (> 1: guiding wins).
# With TIME=T the runs are at equal time instead: `render --time T --spp SPP` (SPP the cap, then
# set it high), each stopping at its first pass boundary after T seconds of rendering (the guide's
# training passes count; set-up and pipelines do not); the runs also print the spp they reached,
# and the ratio compares the relMSEs themselves (and, for the record, relMSE x seconds).
#
#   tools/bench_guiding.sh [DIR] [NUSSELT]
# Environment: SIZE (default 128), SPP (64), REF_SPP (4096), REPEATS (3), DEPTH (8), TIME (unset:
#   equal spp; a number of seconds: equal render time, SPP the cap),
#   SCENES (default: scenes/cornell/cornell-indirect.glb, scenes/tests/guiding_gap.gltf and the
#   default Cornell box, "default"),
#   GUIDE_ARGS (extra options of the guided renders, e.g. "--guide-spatial 1000"),
#   VARIANTS (guided variants' own options, separated by "|", each added to GUIDE_ARGS; default
#   one variant without options, e.g. "--guide-alpha auto|--guide-alpha 0.5"; a variant that
#   starts with "@PATH " runs the binary PATH instead of NUSSELT, e.g. a copy of the previous
#   main's: "|@/tmp/nusselt-old" compares the two interleaved).
# Besides the medians, the means of relMSE over the seeds with their standard errors (the error
# of a guided render is heavy-tailed: a few paths through a poorly learned cell).
# The reference is rendered with --variance and independent random numbers (--rng pcg: its var
# channels, the sample variance over n, are then its mean's variance; under the default quasi-Monte
# Carlo numbers they would overstate it), so `nusselt diff` also gives each run's relMSE less the
# reference's own noise (for a run independent of it, E[relMSE] = the run's error + the
# reference's); printed beside the raw figure, with the ratios of both. The noise of a 4096-spp
# reference is several % of a 10 s unguided run's relMSE and a larger share of a guided run's: the
# raw ratios understate the gains (and the losses). A warning says when the reference's noise is
# above a run's error less it (a 4096-spp reference against 60 s runs at 256 x 256): the figures
# less it then rest on its var channels, and a reference with more REF_SPP is the remedy.
# REGIONS ("NAME:x0,y0,x1,y1 ...", NAME a scene's name as printed; default the glass box's caustic
# under the sphere, "cornell-glass:0.40,0.80,0.60,0.90"): for those scenes each run is also compared
# in that part of the image (`nusselt diff --region`), with its medians and ratio; REGIONS= for none.
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
budget=${TIME:-}
if [ -n "$budget" ]; then
  awk -v t="$budget" 'BEGIN { exit !(t > 0) }' || { echo "TIME=$budget is not a positive number of seconds" >&2; exit 2; }
fi


# `nusselt diff ARGS`'s relMSE and its relMSE less the reference's noise (the raw figure again
# when the reference has no var channels): "RAW NET".
diff_relmse() { "$bin" diff "$@" | awk 'NR == 1 {r = $2} NR == 2 {n = $NF} END {print r, (n == "" ? r : n)}'; }
regions=${REGIONS-"cornell-glass:0.40,0.80,0.60,0.90"}
# The region of scene $1 (empty: none).
scene_region() {
  local r
  for r in $regions; do
    if [ "${r%%:*}" = "$1" ]; then echo "${r#*:}"; return 0; fi
  done
  return 0
}

IFS='|' read -r -a variants <<< "${VARIANTS:-}"
[ ${#variants[@]} -eq 0 ] && variants=("")
modes=(off)
for ((v = 0; v < ${#variants[@]}; v++)); do modes+=("on$v"); done
if [ -n "$budget" ]; then per="$budget s of rendering per run (at most $spp spp)"; else per="$spp spp per run"; fi
echo "bench_guiding: ${size}x${size}, $per, reference $refSpp spp (unguided, pcg), max depth $depth, $repeats repeats, guided with: --guiding on ${GUIDE_ARGS:-}"
# A variant's binary ("@PATH " before its options) and its options.
variant_bin() { local v=${variants[$1]}; if [[ $v == @* ]]; then v=${v%% *}; echo "${v#@}"; else echo "$bin"; fi; }
variant_args() {
  local v=${variants[$1]}
  if [[ $v != @* ]]; then echo "$v"; elif [[ $v == *" "* ]]; then echo "${v#* }"; fi
  return 0
}
# A mode's binary, --guiding value and guided options: sets run, guiding and extra.
mode_setup() {
  run=$bin
  guiding=off
  extra=""
  if [ "$1" != off ]; then
    run=$(variant_bin "${1#on}")
    guiding=on
    extra="${GUIDE_ARGS:-} $(variant_args "${1#on}")"
  fi
}
for ((v = 0; v < ${#variants[@]}; v++)); do
  vb=$(variant_bin $v)
  [ -x "$vb" ] || { echo "variant on$v: no binary $vb" >&2; exit 2; }
  echo "  variant on$v: $(variant_args $v)$([ "$vb" != "$bin" ] && echo " (binary $vb)")"
done
echo "load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)"
echo "device: $("$bin" devices | head -1)"
for scene in $scenes; do
  name=$(scene_name "$scene")
  sceneArg=$(scene_arg "$scene")
  region=$(scene_region "$name")
  ref="$dir/$name-ref-$size-$refSpp-$depth-pcg-var.exr"
  # shellcheck disable=SC2086
  bench_reference "$bin" "$scene" "$ref" "$refSpp" $common --rng pcg --variance
  for mode in "${modes[@]}"; do : > "$dir/$name.$mode"; done
  # One untimed render per mode first: lavapipe compiles a pipeline at its first dispatch (Mesa's
  # disk cache keeps it for later processes), which would otherwise land in the first round's
  # time, and with TIME in its budget (a cold cache once left a guided run 1 spp).
  for mode in "${modes[@]}"; do
    mode_setup "$mode"
    # shellcheck disable=SC2086
    "$run" render $sceneArg $common --width 16 --height 16 --spp 2 --guide-train 1 --guiding "$guiding" $extra -o "$dir/warm-up.exr"
  done
  for ((r = 1; r <= repeats; r++)); do
    for mode in "${modes[@]}"; do
      out="$dir/$name-$mode-$r.exr"
      t0=$(date +%s.%N)
      mode_setup "$mode"
      # shellcheck disable=SC2086
      "$run" render $sceneArg $common --spp "$spp" ${budget:+--time "$budget"} --seed "$r" --guiding "$guiding" $extra -o "$out"
      t1=$(date +%s.%N)
      sec=$(echo "$t1 - $t0" | bc -l)
      read -r rel net < <(diff_relmse "$out" "$ref")  # net: less the reference's noise
      [ -n "$rel" ] || { echo "bench_guiding: nusselt diff $out $ref failed" >&2; exit 1; }
      if awk -v n="$net" 'BEGIN { exit !(n <= 0) }'; then
        echo "warning: $out: its relMSE $rel is not above the reference's own noise (relMSE less it: $net):" \
          "the figures less the reference's noise mean nothing here; render the reference with more REF_SPP" >&2
      elif awk -v r="$rel" -v n="$net" 'BEGIN { exit !(r - n > n) }'; then
        # The subtraction then carries more than the run's own error: a few % off in the
        # reference's var channels moves the figure by more than that.
        echo "warning: $out: the reference's own noise ($(calc "$rel - $net")) is above this run's error less it" \
          "($net): the figures less the reference's noise rest on its var channels; render the reference with more REF_SPP" >&2
      fi
      regionNet=-
      [ -z "$region" ] || read -r _ regionNet < <(diff_relmse "$out" "$ref" --region "$region")
      prod=$(calc "$rel * $sec")
      got=$("$bin" info "$out" | awk '$1 == "nusselt/spp:" {print $2}')
      printf "%-20s guiding %-3s seed %d: relMSE %.5g (less the reference's noise %.5g)  %.2f s  relMSE x s %.5g  %s spp  (load %s)\n" \
        "$name" "$mode" "$r" "$rel" "$net" "$sec" "$prod" "$got" "$(cut -d' ' -f1 /proc/loadavg)"
      [ "$regionNet" = - ] || printf "%-20s guiding %-3s seed %d: region %s: relMSE less the reference's noise %.5g\n" \
        "$name" "$mode" "$r" "$region" "$regionNet"
      echo "$rel $sec $prod $got $net $regionNet" >> "$dir/$name.$mode"
    done
  done
  for mode in "${modes[@]}"; do
    mr=$(awk '{print $1}' "$dir/$name.$mode" | median)
    ms=$(awk '{print $2}' "$dir/$name.$mode" | median)
    mp=$(awk '{print $3}' "$dir/$name.$mode" | median)
    mg=$(awk '{print $4}' "$dir/$name.$mode" | median)
    mn=$(awk '{print $5}' "$dir/$name.$mode" | median)
    printf "%-20s guiding %-3s median: relMSE %.5g (less the reference's noise %.5g)  %.2f s  relMSE x s %.5g  %s spp\n" \
      "$name" "$mode" "$mr" "$mn" "$ms" "$mp" "$mg"
    read -r mm se < <(awk '{print $1}' "$dir/$name.$mode" | mean_se)
    read -r nm nse < <(awk '{print $5}' "$dir/$name.$mode" | mean_se)
    printf "%-20s guiding %-3s mean:   relMSE %.5g +- %.2g (less the reference's noise %.5g +- %.2g)\n" "$name" "$mode" \
      "$mm" "$se" "$nm" "$nse"
    mreg=$(awk '{print $6}' "$dir/$name.$mode" | median)
    eval "g_$mode=$mreg"
    eval "n_$mode=$mn"
    eval "nm_$mode=$nm"
    eval "m_$mode=$mm"
    eval "p_$mode=$mp"
    eval "r_$mode=$mr"
  done
  for mode in "${modes[@]:1}"; do
    rOn=r_$mode
    pOn=p_$mode
    mOn=m_$mode
    nOn=n_$mode
    nmOn=nm_$mode
    printf "%-20s unguided / guided %s: relMSE %.3fx, relMSE x time %.3fx, means %.3fx (> 1: guiding wins)\n" "$name" "$mode" \
      "$(calc "$r_off / ${!rOn}")" "$(calc "$p_off / ${!pOn}")" "$(calc "$m_off / ${!mOn}")"
    printf "%-20s   less the reference's noise: relMSE %.3fx, means %.3fx\n" "$name" \
      "$(calc "$n_off / ${!nOn}")" "$(calc "$nm_off / ${!nmOn}")"
    gOn=g_$mode
    [ -z "$region" ] || printf "%-20s   region %s, less the reference's noise: medians %.5g / %.5g, relMSE %.3fx\n" "$name" \
      "$region" "$g_off" "${!gOn}" "$(calc "$g_off / ${!gOn}")"
  done
done
