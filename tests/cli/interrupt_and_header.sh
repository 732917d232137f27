#!/usr/bin/env bash
# The EXR header carries the render's settings; SIGINT/SIGTERM write what has accumulated with
# its true spp; same seed gives identical pixels.
# Usage: interrupt_and_header.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
attr() { "$nusselt" info "$1" | sed -n "s/^  nusselt\/$2: //p"; }

# Header attributes of a complete render.
"$nusselt" render -o "$work/a.exr" --width 16 --height 12 --spp 3 --seed 9 --max-depth 5 -q || fail "render exit $?"
[ "$(attr "$work/a.exr" spp)" = 3 ] || fail "spp attribute: $(attr "$work/a.exr" spp)"
[ "$(attr "$work/a.exr" seed)" = 9 ] || fail "seed attribute"
[ "$(attr "$work/a.exr" maxDepth)" = 5 ] || fail "maxDepth attribute"
[ "$(attr "$work/a.exr" interrupted)" = 0 ] || fail "interrupted attribute"
[ -n "$(attr "$work/a.exr" device)" ] || fail "device attribute"
[ -n "$(attr "$work/a.exr" version)" ] || fail "version attribute"
[ -n "$(attr "$work/a.exr" integrator)" ] || fail "integrator attribute"
[ -n "$(attr "$work/a.exr" renderSeconds)" ] || fail "renderSeconds attribute"
# The robustness counters (issue 8): dropped non-finite samples and the quadtree sampler's bound
# violations are in every header, and 0 for the default scene.
[ "$(attr "$work/a.exr" nonFiniteSamples)" = 0 ] || fail "nonFiniteSamples attribute: '$(attr "$work/a.exr" nonFiniteSamples)'"
[ "$(attr "$work/a.exr" samplerBoundViolations)" = 0 ] || fail "samplerBoundViolations attribute"
[ -n "$(attr "$work/a.exr" samplerTrialFailures)" ] || fail "samplerTrialFailures attribute"
"$nusselt" info "$work/a.exr" | head -1 | grep -q "16x12" || fail "image size"
# Binned sampling (docs/scenes.md, "Sampling textured materials"): recorded only when the scene used
# bins (the default scene has no textured gltf_pbr); a resume with other bins is refused.
[ -z "$(attr "$work/a.exr" roughnessBins)" ] || fail "roughnessBins attribute without bins"
"$nusselt" render "$2/scenes/tests/textures.gltf" -o "$work/t.exr" --width 16 --height 12 --spp 2 --roughness-bins 4 \
  --roughness-bin-spacing 1.5 -q || fail "textured render exit $?"
[ "$(attr "$work/t.exr" roughnessBins)" = 4 ] || fail "roughnessBins attribute: '$(attr "$work/t.exr" roughnessBins)'"
[ "$(attr "$work/t.exr" roughnessBinSpacing)" = 1.5 ] || fail "roughnessBinSpacing attribute: '$(attr "$work/t.exr" roughnessBinSpacing)'"
if "$nusselt" render "$2/scenes/tests/textures.gltf" -o "$work/t2.exr" --width 16 --height 12 --spp 3 --resume "$work/t.exr" \
  --roughness-bins 8 --roughness-bin-spacing 1.5 -q 2>"$work/resume_err"; then
  fail "a resume with other roughness bins was accepted"
fi
grep -q "roughness bins" "$work/resume_err" || fail "resume error does not name the bins: $(cat "$work/resume_err")"
"$nusselt" render "$2/scenes/tests/textures.gltf" -o "$work/t3.exr" --width 16 --height 12 --spp 3 --resume "$work/t.exr" \
  --roughness-bins 4 --roughness-bin-spacing 1.5 -q || fail "a resume with the same bins was refused"

# Same seed: identical pixels (the header differs only in timings).
"$nusselt" render -o "$work/b.exr" --width 16 --height 12 --spp 3 --seed 9 --max-depth 5 -q
"$nusselt" diff "$work/a.exr" "$work/b.exr" | grep -q "max |diff| 0$" || fail "same seed differs: $("$nusselt" diff "$work/a.exr" "$work/b.exr")"

# Interrupt: a long render stopped by a signal writes a valid EXR with the spp it really has.
for sig in INT TERM; do
  out=$work/int_$sig.exr
  "$nusselt" render -o "$out" --width 32 --height 32 --spp 1000000 2>"$work/stderr_$sig" &
  pid=$!
  # Interrupt once the render loop runs (the setup time varies with the machine's load), plus
  # enough time for a few passes.
  for _ in $(seq 600); do grep -q '^device:' "$work/stderr_$sig" 2>/dev/null && break; sleep 0.5; done
  sleep 2
  kill -$sig $pid
  wait $pid
  status=$?
  [ $status -eq 130 ] || fail "SIG$sig: exit status $status (want 130): $(cat "$work/stderr_$sig")"
  if [ -s "$out" ]; then
    spp=$(attr "$out" spp)
    [ -n "$spp" ] && [ "$spp" -ge 1 ] && [ "$spp" -lt 1000000 ] || fail "SIG$sig: spp attribute '$spp'"
    [ "$(attr "$out" interrupted)" = 1 ] || fail "SIG$sig: interrupted attribute"
    echo "ok   SIG$sig stopped the render at $spp spp"
  else
    fail "SIG$sig: no image written: $(cat "$work/stderr_$sig")"
  fi
done

[ $fails -eq 0 ] && echo "header, determinism and interrupt checks pass"
exit $((fails > 0))
