#!/usr/bin/env bash
# Bit-identity check for refactors: renders a fixed set of small cases (every sampler, lighting
# mode, random-number mode (the default qmc, and pcg) and roulette on the Cornell box; the
# materials scene; the test scenes; combined materials; Metropolis and VEGAS; path guiding with
# its defaults, its options and its photon pre-pass; the dragon) and compares them with a
# recorded set. A refactor must leave
# every pixel and every counter of the header unchanged.
#
#   tools/identity.sh record DIR [NUSSELT]   render the cases into DIR (NUSSELT: default build/nusselt)
#   tools/identity.sh check DIR [NUSSELT]    render them again and compare with DIR: exit 1 on any change
#
# Pixels are compared with `nusselt diff` (max |diff| must be 0); the header's counters (rays,
# shadow rays, dropped samples, sampler violations and failures) with `nusselt info`.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:?usage: tools/identity.sh record|check DIR [NUSSELT]}
dir=${2:?usage: tools/identity.sh record|check DIR [NUSSELT]}
bin=${3:-build/nusselt}
[ -x "$bin" ] || { echo "no binary $bin: build first" >&2; exit 2; }
mkdir -p "$dir"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

small="--width 48 --height 48 --spp 4 --max-depth 6 --seed 11 -q --checkpoint 0"
cases=(
  "cornell-quadtree|$small"
  "cornell-cosine|$small --sampler cosine"
  "cornell-analytic|$small --sampler analytic"
  "cornell-tabulated|$small --sampler tabulated"
  "cornell-uniform|$small --sampler uniform"
  "cornell-nee|$small --lighting nee"
  "cornell-bsdf|$small --lighting bsdf"
  "cornell-pcg|$small --rng pcg"
  "cornell-albedo-roulette|$small --roulette albedo"
  "cornell-offset|$small --spp-offset 5"
  "materials-quadtree|scenes/materials/materials.gltf $small"
  "materials-analytic|scenes/materials/materials.gltf $small --sampler analytic"
  "furnace|scenes/tests/furnace.gltf $small"
  "mis|scenes/tests/mis.gltf $small"
  "punctual|scenes/tests/punctual.gltf $small"
  "combined|scenes/tests/combined.gltf $small"
  "combined-albedo-roulette|scenes/tests/combined.gltf $small --roulette albedo"
  "combined-uniform|scenes/tests/combined.gltf $small --components uniform"
  "combined-uniform-albedo|scenes/tests/combined.gltf $small --components uniform --roulette albedo"
  "cornell-mlt|$small --integrator mlt --mlt-chains 4096"
  "cornell-mlt-indirect|$small --integrator mlt --mlt-chains 4096 --mlt-chain-light indirect --mlt-steps 2"
  "cornell-mlt-direct-in-chain|$small --integrator mlt --mlt-chains 4096 --mlt-direct-spp 0 --mlt-weights plain"
  "glass-mlt|scenes/cornell/cornell-glass.glb $small --integrator mlt --mlt-chains 2048"
  "cornell-vegas|$small --integrator vegas"
  "cornell-guided|$small --spp 8 --guiding on --guide-train 7"
  "indirect-guided|scenes/cornell/cornell-indirect.glb $small --spp 8 --guiding on --guide-train 7"
  "indirect-guided-options|scenes/cornell/cornell-indirect.glb $small --spp 8 --guiding on --guide-train 7 --guide-alpha 0.5 --guide-filter none --guide-spatial-filter box --guide-learn radiance --guide-floor 0.1"
  "glass-guided-photons|scenes/cornell/cornell-glass.glb $small --spp 8 --guiding on --guide-train 7 --guide-photons 20000"
  "dragon|scenes/dragon/dragon.gltf --width 32 --height 32 --spp 2 --max-depth 4 -q --checkpoint 0"
)
counters='nusselt/(guideHash|rays|shadowRays|nonFiniteSamples|bvhStackOverflows|samplerBoundViolations|samplerTrialFailures|spp):'
status=0
for c in "${cases[@]}"; do
  name=${c%%|*}
  args=${c#*|}
  out="$work/$name.exr"
  # shellcheck disable=SC2086
  "$bin" render $args -o "$out"
  "$bin" info "$out" | grep -E "$counters" > "$work/$name.txt" || true
  if [ "$mode" = record ]; then
    cp "$out" "$dir/$name.exr"
    cp "$work/$name.txt" "$dir/$name.txt"
    echo "recorded $name"
    continue
  fi
  line=$("$bin" diff "$out" "$dir/$name.exr")
  if [[ "$line" != *"max |diff| 0" ]] || ! cmp -s "$work/$name.txt" "$dir/$name.txt"; then
    echo "CHANGED $name: $line"
    diff "$dir/$name.txt" "$work/$name.txt" || true
    status=1
  else
    echo "identical $name"
  fi
done
exit $status
