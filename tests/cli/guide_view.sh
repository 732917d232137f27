#!/usr/bin/env bash
# nusselt guide-view (docs/guiding.md): it trains a guide, writes two panels side by side of the
# stated size, and the densities it draws integrate to 1 over the sphere (the guide exactly: the
# panel's cells refine the tree's dyadic cells; the Lambert floor's BRDF sampler within 1 % by the
# midpoint rule on a 256 x 256 map; it prints 1.0000). A pixel outside the image, a pixel
# that sees no surface and a malformed --pixel are errors that name the option, with no output.
# Usage: guide_view.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

# The built-in Cornell box at 32 x 32: pixel (16, 26) sees the floor.
if "$nusselt" guide-view --pixel 16 26 --width 32 --train 3 --size 256 -o "$work/view.png" -q >"$work/out" 2>"$work/err"; then
  cat "$work/out"
  # PNG width and height: big-endian at bytes 16 and 20 (IHDR); 2 x 256 panels and an 8-pixel gap.
  dims=$(od -An -tu1 -j16 -N8 "$work/view.png" | awk '{print $1*16777216+$2*65536+$3*256+$4, $5*16777216+$6*65536+$7*256+$8}')
  [ "$dims" = "520 256" ] || fail "view.png is $dims, expected 520 256"
  grep -q "material 'white' (lambert)" "$work/out" || fail "the floor's material is not named"
  guide=$(sed -n 's/^guide density: integral over the sphere \([0-9.]*\).*/\1/p' "$work/out")
  brdf=$(sed -n 's/^BRDF sampler density: integral over the sphere \([0-9.]*\).*/\1/p' "$work/out")
  awk -v g="$guide" 'BEGIN { exit !(g != "" && g > 0.9999 && g < 1.0001) }' || fail "guide integral '$guide'"
  awk -v b="$brdf" 'BEGIN { exit !(b != "" && b > 0.99 && b < 1.01) }' || fail "BRDF integral '$brdf'"
else
  fail "guide-view: exit status $?: $(cat "$work/err")"
fi

# expect_error NAME TEXT ARGS...: non-zero (not a signal), the message names TEXT, no output.
expect_error() {
  local name=$1 text=$2; shift 2
  "$nusselt" guide-view -o "$work/$name.png" -q "$@" >/dev/null 2>"$work/err"
  local status=$?
  if [ $status -eq 0 ] || [ $status -ge 128 ]; then fail "$name: exit status $status"; return; fi
  [ -e "$work/$name.png" ] && { fail "$name: wrote an image"; return; }
  grep -qF -- "$text" "$work/err" || { fail "$name: message lacks '$text': $(cat "$work/err")"; return; }
  echo "ok   $name: $(cat "$work/err")"
}
expect_error outside "--pixel 40 3" --pixel 40 3 --width 32
expect_error no_surface "meets no surface" --pixel 0 0 --width 32
expect_error one_number "--pixel" --pixel 3 --width 32

[ $fails -eq 0 ] && echo "guide-view behaves" || echo "$fails guide-view cases misbehave"
exit $((fails > 0))
