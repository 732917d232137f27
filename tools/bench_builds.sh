#!/usr/bin/env bash
# bench_builds.sh: two builds of nusselt against each other on the same scenes, interleaved (A, B,
# A, B, ... per scene, so that the shared machine's load falls on both alike): the samples/s that
# `nusselt bench render` prints for each run, their medians and the ratio B / A. For a change's
# before and after figures (docs/performance.md); build each revision first (a git worktree and
# tools/bootstrap.sh, or cmake) and pass the two binaries.
#
#   tools/bench_builds.sh [--repeats N] [--spp N] [--render] [--name-a A] [--name-b B] BIN_A BIN_B SCENE... [-- BENCH ARGS]
#
# SCENE: a glTF file (scenes/cornell-box.glb is the built-in Cornell box). BENCH ARGS go to both builds'
# `bench render` (e.g. --max-depth 16). Prints a Markdown table.
# --render: whole renders instead (`nusselt render SCENE --width 256 --height 256 --spp N --seed R`
# for repeat R, BENCH ARGS appended): the render seconds of the EXR header (nusselt/renderSeconds:
# the passes, set-up excluded), and whether the two builds' images of each seed are identical
# (`nusselt diff`: max |diff| 0) or their relMSE otherwise. bench render times the ray and shadow
# dispatches of a bounce apart (for its GPU time per stage), renders trace them in one dispatch.
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/bench_lib.sh
repeats=3
spp=8
name_a=A
name_b=B
usage() { sed -n '8,16p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
mode=bench
while [ $# -gt 0 ]; do
  case $1 in
    --repeats) repeats=${2:?}; shift 2 ;;
    --spp) spp=${2:?}; shift 2 ;;
    --render) mode=render; shift ;;
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

if [ "$mode" = render ]; then
  tmp=$(mktemp -d)
  trap 'rm -rf "$tmp"' EXIT
  # render_run BIN SCENE SEED OUT ARGS...: prints the render seconds of the header.
  render_run() {
    local bin=$1 scene=$2 seed=$3 out=$4
    shift 4
    "$bin" render "$scene" --width 256 --height 256 --spp "$spp" --seed "$seed" -q --checkpoint 0 -o "$out" "$@" ||
      { echo "bench_builds.sh: $bin render $scene failed" >&2; exit 1; }
    exr_attr "$bin" "$out" renderSeconds
  }
  echo "Produced by \`tools/bench_builds.sh --render --repeats $repeats --spp $spp${*:+ -- $*}\` on $(date -u '+%Y-%m-%d %H:%M UTC'); $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start; $name_a = $bin_a, $name_b = $bin_b. Render seconds (EXR header) of \`nusselt render\` (256 x 256, $spp spp, seeds 1-$repeats), runs in order, medians in bold; images: the two builds' renders of each seed compared."
  echo
  echo "| scene | $name_a s | $name_b s | $name_a / $name_b | images |"
  echo "|---|---|---|---|---|"
  for s in "${scenes[@]}"; do
    va=() vb=() same=0 diffs=()
    for r in $(seq "$repeats"); do
      va+=("$(render_run "$bin_a" "$s" "$r" "$tmp/a.exr" "$@")")
      vb+=("$(render_run "$bin_b" "$s" "$r" "$tmp/b.exr" "$@")")
      d=$("$bin_a" diff "$tmp/b.exr" "$tmp/a.exr")
      if [[ $d == *"max |diff| 0" ]]; then same=$((same + 1)); else diffs+=("$(echo "$d" | awk '{print $2}')"); fi
    done
    ma=$(printf '%s\n' "${va[@]}" | median)
    mb=$(printf '%s\n' "${vb[@]}" | median)
    if [ "$same" = "$repeats" ]; then img="identical ($same of $repeats)"; else img="$same of $repeats identical; relMSE B vs A ${diffs[*]}"; fi
    printf '| %s | %s **%.3f** | %s **%.3f** | %.2fx | %s |\n' "$(scene_name "$s")" "$(printf "%.3f " "${va[@]}" | sed "s/ $//")" "$ma" \
      "$(printf "%.3f " "${vb[@]}" | sed "s/ $//")" "$mb" "$(calc "$ma / $mb")" "$img"
  done
  exit 0
fi

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
