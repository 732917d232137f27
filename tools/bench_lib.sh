# bench_lib.sh: shell functions shared by the interleaved A/B benchmark scripts of tools/
# (bench_builds.sh, bench_integrator.sh, bench_mlt.sh, bench_vegas.sh, bench_guiding.sh, bench_binned_render.sh,
# bench_samples_per_pass.sh). Sourced, not run.

# calc EXPR: the arithmetic expression EXPR in awk (bc cannot read numbers printed as 1.5e-05,
# which small relMSEs are).
calc() { awk "BEGIN { print $* }"; }

# The median of the numbers on stdin, one per line.
median() { sort -g | awk '{v[NR] = $1} END {if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
# The mean of a column of numbers and its standard error (sample standard deviation / sqrt(n); 0
# for one number): "MEAN SE".
mean_se() { awk '{s += $1; q += $1 * $1; n++} END {m = s / n; v = n > 1 ? (q - n * m * m) / (n - 1) : 0; if (v < 0) v = 0; printf "%.6g %.6g\n", m, sqrt(v / n)}'; }

# A scene's short name: its file name without .gltf/.glb ("default": the built-in Cornell box).
scene_name() { basename "${1%.gltf}" .glb; }

# The render command's scene argument: none for "default", else the path.
scene_arg() { if [ "$1" != default ]; then echo "$1"; fi; }

# bench_reference BIN SCENE REF SPP OPTIONS...: renders the converged reference REF of SCENE once
# (seed 1000, SPP samples, the runs' OPTIONS); kept when REF exists, so reruns reuse it.
bench_reference() {
  local bin=$1 scene=$2 ref=$3 spp=$4
  shift 4
  [ -f "$ref" ] && return 0
  echo "$(scene_name "$scene"): rendering the reference ($spp spp)..."
  # shellcheck disable=SC2046
  "$bin" render $(scene_arg "$scene") "$@" --spp "$spp" --seed 1000 -o "$ref"
}

# exr_attr BIN FILE NAME: the value of the header attribute nusselt/NAME of FILE (`BIN info`).
exr_attr() { "$1" info "$2" | sed -n "s/^  nusselt\/$3: //p" | head -1; }
