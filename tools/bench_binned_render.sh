#!/usr/bin/env bash
# Binned sampling (--roughness-bins BINS) against cosine sampling (--roughness-bins 0) of the
# textured gltf_pbr COMPONENT of a combined material in a render (docs/strategies.md, "Binned
# sampling of textured gltf_pbr"): scenes/tests/textures.gltf with KHR_materials_transmission 0.3
# added to its textured floor (glTF's transmission combination: gltf_pbr and glass, the gltf_pbr
# component's parameters varied by the metallic-roughness texture), written to DIR. SIZE x SIZE,
# SPP samples per pixel, seeds 1 .. SEEDS, interleaved (binned, cosine, binned, cosine, ...), each
# against one converged reference (REF_SPP, binned, seed 1000; kept in DIR, reruns reuse it):
# relMSE from `nusselt diff`, the render's sampling seconds (header nusselt/renderSeconds) and
# relMSE x s (lower is better), per run and as medians, and the ratio cosine / binned of the
# medians (> 1: binned wins). Prints a markdown table. A benchmark, not a test.
#   tools/bench_binned_render.sh [DIR] [NUSSELT]
# Environment: SIZE (96), SPP (64), REF_SPP (16384), SEEDS (3), DEPTH (8), BINS (16).
set -euo pipefail
cd "$(dirname "$0")/.."
dir=${1:-/tmp/nusselt-bench-binned}
bin=${2:-build/nusselt}
[ -x "$bin" ] || { echo "no binary $bin: build first" >&2; exit 2; }
size=${SIZE:-96}
spp=${SPP:-64}
refSpp=${REF_SPP:-16384}
seeds=${SEEDS:-3}
depth=${DEPTH:-8}
bins=${BINS:-16}
mkdir -p "$dir"
# shellcheck source=tools/bench_lib.sh
source tools/bench_lib.sh
attr() { exr_attr "$bin" "$1" "$2"; }

scene="$dir/textures-transmission.gltf"
python3 - scenes/tests/textures.gltf "$scene" <<'PY'
import json, sys
g = json.load(open(sys.argv[1]))
floor = [m for m in g["materials"] if m.get("name") == "floor"]
if len(floor) != 1 or "metallicRoughnessTexture" not in floor[0].get("pbrMetallicRoughness", {}):
    sys.exit(sys.argv[1] + ": no material 'floor' with a metallicRoughnessTexture")
floor[0].setdefault("extensions", {})["KHR_materials_transmission"] = {"transmissionFactor": 0.3}
used = g.setdefault("extensionsUsed", [])
if "KHR_materials_transmission" not in used:
    used.append("KHR_materials_transmission")
json.dump(g, open(sys.argv[2], "w"))
PY
common="--width $size --height $size --max-depth $depth -q --checkpoint 0"
ref="$dir/ref-$size-$refSpp-$depth-$bins.exr"
# shellcheck disable=SC2086
bench_reference "$bin" "$scene" "$ref" "$refSpp" $common --roughness-bins "$bins"
[ "$(attr "$ref" roughnessBins)" = "$bins" ] || { echo "$ref: the reference did not use $bins bins" >&2; exit 1; }

echo "bench_binned_render: textures.gltf + KHR_materials_transmission 0.3 on the floor, ${size}x${size}, $spp spp," \
     "max depth $depth, seeds 1-$seeds, interleaved; reference $refSpp spp (--roughness-bins $bins, seed 1000)"
echo "device: $("$bin" devices | head -1); load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| run | relMSE | render s | relMSE x s |"
echo "|---|---|---|---|"
: > "$dir/binned"; : > "$dir/cosine"
for ((s = 1; s <= seeds; s++)); do
  for mode in binned cosine; do
    k=$([ $mode = binned ] && echo "$bins" || echo 0)
    out="$dir/$mode-$s.exr"
    # shellcheck disable=SC2086
    "$bin" render "$scene" $common --spp "$spp" --seed "$s" --roughness-bins "$k" -o "$out"
    used=$(attr "$out" roughnessBins)
    if [ $mode = binned ] && [ "$used" != "$bins" ]; then echo "$out: no bins used" >&2; exit 1; fi
    if [ $mode = cosine ] && [ -n "$used" ]; then echo "$out: bins used" >&2; exit 1; fi
    rel=$("$bin" diff "$out" "$ref" | awk '{print $2}')
    sec=$(attr "$out" renderSeconds)
    prod=$(calc "$rel * $sec")
    printf "| %s (K = %s), seed %d | %.5g | %.3f | %.5g |\n" "$mode" "$k" "$s" "$rel" "$sec" "$prod"
    echo "$rel $sec $prod" >> "$dir/$mode"
  done
done
for mode in binned cosine; do
  printf "| %s, median | %.5g | %.3f | %.5g |\n" "$mode" "$(awk '{print $1}' "$dir/$mode" | median)" \
    "$(awk '{print $2}' "$dir/$mode" | median)" "$(awk '{print $3}' "$dir/$mode" | median)"
done
rb=$(awk '{print $1}' "$dir/binned" | median); rc=$(awk '{print $1}' "$dir/cosine" | median)
pb=$(awk '{print $3}' "$dir/binned" | median); pc=$(awk '{print $3}' "$dir/cosine" | median)
echo
printf "cosine / binned: relMSE %.3f, relMSE x s %.3f\n" "$(calc "$rc / $rb")" "$(calc "$pc / $pb")"
