#!/usr/bin/env bash
# Measured materials (merl, docs/measured.md) through the command line: a Cornell box whose white
# material reads a MERL file written by make_merl renders like the analytic one it tabulates; bad
# files and paths are errors naming the file, with a non-zero exit and no output image.
# Usage: measured.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
src=$2
make_merl=$(dirname "$nusselt")/make_merl
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export NUSSELT_CACHE_DIR=$work/cache
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

mkdir -p "$work/scene"
"$make_merl" --model lambert --param rho=0.5 -o "$work/scene/white.binary" >/dev/null || { echo "FAIL make_merl"; exit 1; }

# scene NAME MATERIAL_JSON: the Cornell box (scenes/cornell-box.glb) with its "white" material's
# NUSSELT_brdf replaced, written as $work/scene/NAME.glb.
scene() {
  python3 - "$src/scenes/cornell-box.glb" "$work/scene/$1.glb" "$2" <<'PY'
import json, struct, sys
data = open(sys.argv[1], 'rb').read()
n = struct.unpack('<I', data[12:16])[0]
doc = json.loads(data[20:20 + n])
rest = data[20 + n:]
for m in doc['materials']:
    if m['name'] == 'white':
        m['extensions']['NUSSELT_brdf'] = json.loads(sys.argv[3])
js = json.dumps(doc).encode()
js += b' ' * (-len(js) % 4)
out = struct.pack('<III', 0x46546C67, 2, 12 + 8 + len(js) + len(rest)) + struct.pack('<II', len(js), 0x4E4F534A) + js + rest
open(sys.argv[2], 'wb').write(out)
PY
}
scene analytic '{"model": "lambert", "params": {"rho": 0.5}}'
scene measured '{"model": "merl", "file": "white.binary"}'

# The same random numbers and f equal to float rounding: the two renders agree to far better than
# 1e-3. Both sample by cosine: under the quadtree, lambert (a constant BRDF) is sampled by cosine
# and the table by its trees, so the two would draw different directions from the same numbers
# (the table's trees are tested by Merl.ChiSquareCpu and MerlGpu.ChiSquareAndParity).
args=(--spp 4 --width 48 --height 48 --seed 7 -q --sampler cosine)
"$nusselt" render "$work/scene/analytic.glb" -o "$work/analytic.exr" "${args[@]}" 2>"$work/stderr" || fail "analytic render: $(cat "$work/stderr")"
mean() { "$nusselt" info "$1" 2>&1 | sed -n 's/.*mean[^0-9-]*\([0-9.e+-]*\).*/\1/p' | head -1; }
if "$nusselt" render "$work/scene/measured.glb" -o "$work/measured.exr" "${args[@]}" 2>"$work/stderr"; then
  a=$(mean "$work/analytic.exr"); m=$(mean "$work/measured.exr")
  if python3 -c "import sys; a, m = float('$a'), float('$m'); sys.exit(0 if a > 0 and abs(a - m) <= 1e-3 * a else 1)"; then
    echo "ok   render: mean $m (analytic lambert $a)"
  else
    fail "render: mean $m, analytic lambert $a"
  fi
else
  fail "measured render: $(cat "$work/stderr")"
fi

# The same as one component of a combined material (the components' albedo tables on the CPU, the
# table in the combined shade stage on the GPU).
scene analytic2 '{"components": [{"model": "lambert", "weight": 0.5, "params": {"rho": 0.5}}, {"model": "phong", "weight": 0.5}]}'
scene measured2 '{"components": [{"model": "merl", "weight": 0.5, "file": "white.binary"}, {"model": "phong", "weight": 0.5}]}'
if "$nusselt" render "$work/scene/analytic2.glb" -o "$work/analytic2.exr" "${args[@]}" 2>"$work/stderr" &&
   "$nusselt" render "$work/scene/measured2.glb" -o "$work/measured2.exr" "${args[@]}" 2>"$work/stderr"; then
  a=$(mean "$work/analytic2.exr"); m=$(mean "$work/measured2.exr")
  if python3 -c "import sys; a, m = float('$a'), float('$m'); sys.exit(0 if a > 0 and abs(a - m) <= 1e-3 * a else 1)"; then
    echo "ok   combined render: mean $m (analytic $a)"
  else
    fail "combined render: mean $m, analytic $a"
  fi
else
  fail "combined render: $(cat "$work/stderr")"
fi

# expect_error NAME MATERIAL_JSON EXPECTED_TEXT...: the scene with that material fails cleanly.
expect_error() {
  local name=$1 material=$2; shift 2
  scene "$name" "$material"
  local out=$work/$name.exr
  "$nusselt" render "$work/scene/$name.glb" -o "$out" --spp 1 --width 8 --height 8 -q >/dev/null 2>"$work/stderr"
  local status=$? msg
  msg=$(cat "$work/stderr")
  if [ $status -eq 0 ] || [ $status -ge 128 ]; then fail "$name: exit status $status: $msg"; return; fi
  if [ -e "$out" ]; then fail "$name: wrote $out"; return; fi
  for e in "$@"; do
    if ! grep -qF -- "$e" <<<"$msg"; then fail "$name: message lacks '$e': $msg"; return; fi
  done
  echo "ok   $name: $msg"
}
cp "$work/scene/white.binary" "$work/outside.binary"
head -c 1000 "$work/scene/white.binary" >"$work/scene/truncated.binary"
{ printf '\x5a\x00\x00\x00\x5a\x00\x00\x00\x68\x01\x00\x00'; tail -c +13 "$work/scene/white.binary"; } >"$work/scene/header.binary"
python3 - "$work/scene/white.binary" "$work/scene/nan.binary" <<'PY'
import struct, sys
b = bytearray(open(sys.argv[1], 'rb').read())
b[12 + 8 * 1000:12 + 8 * 1001] = struct.pack('<d', float('nan'))
open(sys.argv[2], 'wb').write(b)
PY
expect_error outside '{"model": "merl", "file": "../outside.binary"}' "outside.binary" "leave the scene directory"
expect_error absolute "{\"model\": \"merl\", \"file\": \"$work/outside.binary\"}" "outside.binary" "absolute paths are refused"
expect_error missing '{"model": "merl", "file": "nowhere.binary"}' "nowhere.binary"
expect_error truncated '{"model": "merl", "file": "truncated.binary"}' "truncated.binary" "truncated"
expect_error header '{"model": "merl", "file": "header.binary"}' "header.binary" "dimension header (90, 90, 360)"
expect_error nan '{"model": "merl", "file": "nan.binary"}' "nan.binary" "is NaN"
expect_error nofile '{"model": "merl"}' "materials[" "needs \"file\""
expect_error params '{"model": "merl", "file": "white.binary", "params": {"rho": 1}}' "has no \"params\""

# The command line: albedo by quadrature and samples from a file.
a=$("$nusselt" albedo --model merl --file "$work/scene/white.binary" --theta 60 2>/dev/null)
python3 -c "import sys; sys.exit(0 if abs(float('$a') - 0.5) <= 1e-4 else 1)" && echo "ok   albedo: $a" || fail "albedo: '$a'"
"$nusselt" sample --model merl --file "$work/scene/white.binary" --theta 30 -n 1000 --cpu -o "$work/s.csv" 2>"$work/stderr" \
  && [ "$(wc -l <"$work/s.csv")" -ge 1000 ] && echo "ok   sample" || fail "sample: $(cat "$work/stderr")"
if "$nusselt" albedo --model merl --file "$work/scene/truncated.binary" --theta 0 >/dev/null 2>"$work/stderr"; then fail "albedo of a truncated file succeeded"
elif grep -qF "truncated.binary: truncated" "$work/stderr"; then echo "ok   albedo bad file: $(cat "$work/stderr")"
else fail "albedo bad file: $(cat "$work/stderr")"; fi

[ $fails -eq 0 ] && echo "all measured-material cases behave" || echo "$fails measured-material cases misbehave"
exit $((fails > 0))
