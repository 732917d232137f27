#!/usr/bin/env bash
# The environment options (issue 17): bad maps and option values fail with a message naming the
# file or the option, a non-zero exit and no output; a scene without light warns and renders in the
# default white environment, --env none keeps it black; the EXR header and `info` record the
# environment, scale and rotation, and --resume refuses a different one.
# Usage: environment.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
src=$2
scene=$src/scenes/tests/environment.gltf
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

# Maps written here (Radiance RGBE, flat pixels): 4 x 2 of radiance ~1 (mantissa 128, exponent
# 129: (128.5 / 256) 2^1), a 3 x 2 one (not 2:1), a truncated one and a text file.
pixel='\x80\x80\x80\x81'
printf "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 4\n$(for i in 1 2 3 4 5 6 7 8; do printf '%s' "$pixel"; done)" >"$work/ok.hdr"
printf "#?RADIANCE\n\n-Y 2 +X 3\n$(for i in 1 2 3 4 5 6; do printf '%s' "$pixel"; done)" >"$work/wide.hdr"
printf "#?RADIANCE\n\n-Y 2 +X 4\n$pixel$pixel" >"$work/truncated.hdr"
echo "not an image" >"$work/text.hdr"

# expect_error NAME EXPECTED_TEXT... -- ARGS...
expect_error() {
  local name=$1; shift
  local expected=()
  while [ "$1" != "--" ]; do expected+=("$1"); shift; done
  shift
  local out=$work/$name.exr
  "$nusselt" render "$scene" -o "$out" --spp 1 --width 8 --height 4 -q "$@" >"$work/stdout" 2>"$work/stderr"
  local status=$?
  local msg
  msg=$(cat "$work/stderr")
  if [ $status -eq 0 ] || [ $status -ge 128 ]; then fail "$name: exit status $status (want 1 or 2)"; return; fi
  if [ -e "$out" ]; then fail "$name: wrote $out"; return; fi
  for e in "${expected[@]}"; do
    if ! grep -qF -- "$e" <<<"$msg"; then fail "$name: message lacks '$e': $msg"; return; fi
  done
  echo "ok   $name: $msg"
}

expect_error missing_map "$work/nope.exr" -- --env "$work/nope.exr"
expect_error directory_map "$work" "directory" -- --env "$work"
expect_error text_map "$work/text.hdr" "unknown format" -- --env "$work/text.hdr"
expect_error truncated_map "$work/truncated.hdr" "truncated" -- --env "$work/truncated.hdr"
expect_error bad_color "--env-color" -- --env-color 1,2
expect_error negative_color "--env-color" -- --env-color 1,-1,1
expect_error map_and_color "--env-color" "--env" -- --env "$work/ok.hdr" --env-color 1,1,1
expect_error negative_scale "--env-scale" -- --env-color 1,1,1 --env-scale -2
expect_error nan_rotate "--env-rotate" -- --env-color 1,1,1 --env-rotate nan

# A map that is not 2:1 renders, with a warning naming it.
if "$nusselt" render "$scene" -o "$work/wide.exr" --spp 1 --width 8 --height 4 --env "$work/wide.hdr" 2>"$work/stderr" >/dev/null &&
   grep -qF "$work/wide.hdr" "$work/stderr" && grep -qF "not 2:1" "$work/stderr" && [ -e "$work/wide.exr" ]; then
  echo "ok   wide_map warns"
else
  fail "wide_map: $(cat "$work/stderr")"
fi

# No light: a warning naming the options, the default white environment (the background is 1).
if "$nusselt" render "$scene" -o "$work/default.exr" --spp 1 --width 8 --height 4 2>"$work/stderr" >/dev/null &&
   grep -qF "has no light" "$work/stderr" && grep -qF -- "--env none" "$work/stderr" &&
   "$nusselt" info "$work/default.exr" | grep -qF "nusselt/environment: uniform 1,1,1"; then
  echo "ok   no_light warns and renders in white"
else
  fail "no_light: $(cat "$work/stderr")"
fi
# --env none: black on purpose, no warning.
if "$nusselt" render "$scene" -o "$work/black.exr" --spp 1 --width 8 --height 4 --env none 2>"$work/stderr" >/dev/null &&
   ! grep -q "has no light" "$work/stderr" && "$nusselt" info "$work/black.exr" | grep -qF "mean RGB 0 0 0"; then
  echo "ok   env_none is black"
else
  fail "env_none: $(cat "$work/stderr"; "$nusselt" info "$work/black.exr")"
fi

# The header records the map, scale and rotation; --resume refuses another scale.
"$nusselt" render "$scene" -o "$work/map.exr" --spp 2 --width 8 --height 4 -q --env "$work/ok.hdr" --env-scale 2 \
  --env-rotate 30 || fail "map render failed"
info=$("$nusselt" info "$work/map.exr")
for want in "nusselt/environment: map $work/ok.hdr" "nusselt/envScale: 2" "nusselt/envRotate: 30"; do
  grep -qF "$want" <<<"$info" && echo "ok   header has '$want'" || fail "header lacks '$want': $info"
done
if "$nusselt" render "$scene" --resume "$work/map.exr" --spp 4 --width 8 --height 4 -q --env "$work/ok.hdr" \
     --env-scale 3 --env-rotate 30 2>"$work/stderr"; then
  fail "resume with another --env-scale was accepted"
elif grep -qF -- "--env-scale" "$work/stderr"; then
  echo "ok   resume refuses another scale: $(cat "$work/stderr")"
else
  fail "resume message: $(cat "$work/stderr")"
fi
"$nusselt" render "$scene" --resume "$work/map.exr" --spp 4 --width 8 --height 4 -q --env "$work/ok.hdr" \
  --env-scale 2 --env-rotate 30 && echo "ok   resume with the same environment" || fail "resume with the same environment"

# The preview takes the same options and accumulates the same film as `render` (under Xvfb, from
# the xvfb package of tools/bootstrap.sh, as tests/cli/preview.sh).
"$nusselt" render "$scene" -o "$work/r.exr" --spp 3 --width 16 --height 8 -q --env "$work/ok.hdr" --env-rotate 30 \
  --env-scale 0.5 || fail "render for the preview comparison"
if xvfb-run -a "$nusselt" preview "$scene" --width 16 --height 8 --max-spp 3 --frames 8 --exr "$work/p.exr" -q \
     --env "$work/ok.hdr" --env-rotate 30 --env-scale 0.5 2>"$work/stderr" &&
   "$nusselt" diff "$work/p.exr" "$work/r.exr" | grep -qE "max \|diff\| 0$" &&
   "$nusselt" info "$work/p.exr" | grep -qF "nusselt/envRotate: 30"; then
  echo "ok   preview with --env equals render"
else
  fail "preview with --env: $(cat "$work/stderr"; "$nusselt" diff "$work/p.exr" "$work/r.exr" 2>&1)"
fi

[ $fails -eq 0 ] && echo "all environment CLI checks passed" || echo "$fails failures"
exit $((fails > 0))
