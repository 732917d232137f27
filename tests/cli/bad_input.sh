#!/usr/bin/env bash
# Bad input gives a clear message naming the file and the field, a non-zero exit, no output
# file and never a crash (exit status >= 128 would be a signal).
# Usage: bad_input.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
src=$2
data=$src/tests/data/gltf
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0

# expect_error NAME EXPECTED_TEXT... -- ARGS...
expect_error() {
  local name=$1; shift
  local expected=()
  while [ "$1" != "--" ]; do expected+=("$1"); shift; done
  shift
  local out=$work/$name.exr
  "$nusselt" render -o "$out" --spp 1 --width 8 --height 8 -q "$@" >"$work/stdout" 2>"$work/stderr"
  local status=$?
  local msg
  msg=$(cat "$work/stderr")
  if [ $status -eq 0 ] || [ $status -ge 128 ]; then
    echo "FAIL $name: exit status $status (want 1 or 2)"; fails=$((fails + 1)); return
  fi
  if [ -e "$out" ]; then echo "FAIL $name: wrote $out"; fails=$((fails + 1)); return; fi
  if ls "$work"/.*tmp* >/dev/null 2>&1; then echo "FAIL $name: left a temporary file"; fails=$((fails + 1)); return; fi
  for e in "${expected[@]}"; do
    if ! grep -qF -- "$e" <<<"$msg"; then
      echo "FAIL $name: message lacks '$e': $msg"; fails=$((fails + 1)); return
    fi
  done
  echo "ok   $name: $msg"
}

expect_error missing_file "does-not-exist.gltf" -- "$work/does-not-exist.gltf"
expect_error malformed_json "malformed.gltf" -- "$data/malformed.gltf"
expect_error truncated_glb "truncated.glb" -- "$data/truncated.glb"
expect_error accessor_oob "accessor_oob.gltf" "accessors[" -- "$data/accessor_oob.gltf"
expect_error index_oob "index_oob.gltf" -- "$data/index_oob.gltf"
expect_error unknown_model "unknown_model.gltf" "materials[" -- "$data/unknown_model.gltf"
expect_error unknown_param "unknown_param.gltf" "parameter" -- "$data/unknown_param.gltf"
expect_error param_range "param_range.gltf" "range" -- "$data/param_range.gltf"
expect_error uri_escape "uri_escape.gltf" -- "$data/uri_escape.gltf"
expect_error uri_absolute "uri_absolute.gltf" -- "$data/uri_absolute.gltf"
expect_error uri_directory "uri_directory.gltf" -- "$data/uri_directory.gltf"
expect_error spp_zero "--spp" -- --spp 0
expect_error unknown_camera "no-such-camera" -- --camera no-such-camera
expect_error bad_output_dir "$work/no/such/dir" -- -o "$work/no/such/dir/x.exr"
expect_error bad_lighting "--lighting" -- --lighting nonsense
expect_error width_zero "--width" -- --width 0
expect_error device_memory "device memory" -- --width 60000 --height 4000

# No Vulkan driver (the loader finds no ICD): a message naming the Debian package, exit 1.
if VK_ICD_FILENAMES=/nonexistent/icd.json "$nusselt" render -o "$work/nodriver.exr" --spp 1 --width 8 -q 2>"$work/stderr"; then
  echo "FAIL no_driver: exit status 0"; fails=$((fails + 1))
elif grep -q "mesa-vulkan-drivers" "$work/stderr" && [ ! -e "$work/nodriver.exr" ]; then
  echo "ok   no_driver: $(cat "$work/stderr")"
else
  echo "FAIL no_driver: $(cat "$work/stderr")"; fails=$((fails + 1))
fi

# Degenerate geometry is not an error: dropped, counted in one warning, and the scene renders.
out=$work/degenerate.exr
if "$nusselt" render "$data/degenerate.gltf" -o "$out" --spp 1 --width 8 --height 8 2>"$work/stderr"; then
  if grep -q "dropped" "$work/stderr" && [ -s "$out" ]; then echo "ok   degenerate: $(grep dropped "$work/stderr")"
  else echo "FAIL degenerate: no warning or no image"; fails=$((fails + 1)); fi
else
  echo "FAIL degenerate: exit status $?: $(cat "$work/stderr")"; fails=$((fails + 1))
fi

# nusselt diff --region: a malformed region is a usage error naming the option, never a crash.
"$nusselt" render -o "$work/small.exr" --spp 1 --width 8 --height 8 -q || { echo "FAIL diff: no image"; fails=$((fails + 1)); }
for region in 0.5,0.5 0.1,0.1,0.2,0.3,0.4 0.5,0,0.2,1 nan,0,1,1 0,x,1,1 -0.1,0,1,1; do
  "$nusselt" diff --region "$region" "$work/small.exr" "$work/small.exr" >"$work/stdout" 2>"$work/stderr"
  status=$?
  if [ $status -eq 0 ] || [ $status -ge 128 ] || ! grep -qF -- "--region" "$work/stderr"; then
    echo "FAIL diff_region $region: exit status $status: $(cat "$work/stderr")"; fails=$((fails + 1))
  else echo "ok   diff_region $region: $(cat "$work/stderr")"; fi
done
line=$("$nusselt" diff --region 0.25,0.5,0.75,1 "$work/small.exr" "$work/small.exr")
[[ "$line" == relMSE\ 0\ * ]] || { echo "FAIL diff_region: a region of an image against itself: $line"; fails=$((fails + 1)); }

[ $fails -eq 0 ] && echo "all bad-input cases behave" || echo "$fails bad-input cases misbehave"
exit $((fails > 0))
