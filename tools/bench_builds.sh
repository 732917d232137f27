#!/usr/bin/env bash
# bench_builds.sh: two builds of nusselt against each other on the same scenes, interleaved (A, B,
# A, B, ... per scene, so that the shared machine's load falls on both alike): the samples/s that
# `nusselt bench render` prints for each run, their medians and the ratio B / A. For a change's
# before and after figures (docs/performance.md); build each revision first (a git worktree and
# tools/bootstrap.sh, or cmake) and pass the two binaries.
#
#   tools/bench_builds.sh [--repeats N] [--spp N] [--name-a A] [--name-b B] BIN_A BIN_B SCENE... [-- BENCH ARGS]
#
# SCENE: a glTF file (scenes/cornell-box.glb is the built-in Cornell box). BENCH ARGS go to both builds'
# `bench render` (e.g. --max-depth 16). Prints a Markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/bench_lib.sh
repeats=3
spp=8
name_a=A
name_b=B
usage() { sed -n '8,11p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case $1 in
    --repeats) repeats=${2:?}; shift 2 ;;
    --spp) spp=${2:?}; shift 2 ;;
    --name-a) name_a=${2:?}; shift 2 ;;
    --name-b) name_b=${2:?}; shift 2 ;;
    -h|--help) usage ;;
    *) break ;;
  esac
done
[ $# -ge 3 ] || usage
bin_a=$1 bin_b=$2
shift 2
scenes=()
while [ $# -gt 0 ] && [ "$1" != -- ]; do scenes+=("$1"); shift; done
[ $# -gt 0 ] && shift
for b in "$bin_a" "$bin_b"; do [ -x "$b" ] || { echo "bench_builds.sh: no executable $b" >&2; exit 2; }; done
for s in "${scenes[@]}"; do
  [ -f "$s" ] || { echo "bench_builds.sh: no scene $s" >&2; exit 2; }
done

# One bench run: "samples/s triangles" from the table row of the scene.
run() {
  local bin=$1 scene=$2
  shift 2
  "$bin" bench render "$scene" --spp "$spp" "$@" 2>&1 |
    awk -v s="$(basename "$scene")" '$1 == s {print $8, $2; found = 1} END {exit !found}' ||
    { echo "bench_builds.sh: $bin bench render $scene printed no figures" >&2; exit 1; }
}

echo "Produced by \`tools/bench_builds.sh --repeats $repeats --spp $spp${*:+ -- $*}\` on $(date -u '+%Y-%m-%d %H:%M UTC'); $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start; $name_a = $bin_a, $name_b = $bin_b. Samples/s of \`nusselt bench render\` (256 x 256), runs in order, medians in bold."
echo
echo "| scene (triangles) | $name_a | $name_b | $name_b / $name_a |"
echo "|---|---|---|---|"
for s in "${scenes[@]}"; do
  va=() vb=() tris=
  for _ in $(seq "$repeats"); do
    read -r v tris < <(run "$bin_a" "$s" "$@")
    va+=("$v")
    read -r v tris < <(run "$bin_b" "$s" "$@")
    vb+=("$v")
  done
  ma=$(printf '%.0f' "$(printf '%s\n' "${va[@]}" | median)")
  mb=$(printf '%.0f' "$(printf '%s\n' "${vb[@]}" | median)")
  printf '| %s (%s) | %s **%s** | %s **%s** | %.2fx |\n' "$(scene_name "$s")" "$tris" "${va[*]}" "$ma" "${vb[*]}" "$mb" \
    "$(calc "$mb / $ma")"
done
