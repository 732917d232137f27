#!/usr/bin/env bash
# --traversal auto|rayquery|bvh: the traversal that ran is in the summary and the EXR header; a
# device without ray queries (simulated with NUSSELT_FAULT_NO_RAY_QUERY=1) falls back to the BVH
# under auto and refuses rayquery with a message; bench render interleaves traversals.
# Usage: traversal.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
attr() { "$nusselt" info "$1" | sed -n "s/^  nusselt\/$2: //p"; }
small=(--width 12 --height 12 --spp 2 --sampler cosine)

"$nusselt" devices >"$work/devices" || fail "devices exit $?"
grep -q "ray queries" "$work/devices" || fail "devices does not say whether ray queries exist: $(cat "$work/devices")"
hasRq=0
grep -q "^0: .*, ray queries)" "$work/devices" && hasRq=1

"$nusselt" render "${small[@]}" --traversal bvh -o "$work/bvh.exr" 2>"$work/bvh.err" || fail "bvh render exit $?"
[ "$(attr "$work/bvh.exr" traversal)" = bvh ] || fail "bvh: header traversal '$(attr "$work/bvh.exr" traversal)'"
grep -q "traversal bvh" "$work/bvh.err" || fail "bvh: summary does not name the traversal: $(cat "$work/bvh.err")"

"$nusselt" render "${small[@]}" -o "$work/auto.exr" 2>"$work/auto.err" || fail "auto render exit $?"
t=$(attr "$work/auto.exr" traversal)
{ [ "$t" = bvh ] || [ "$t" = rayquery ]; } || fail "auto: header traversal '$t' (want the one used)"
grep -q "traversal $t" "$work/auto.err" || fail "auto: summary and header differ: $(cat "$work/auto.err")"

if [ $hasRq = 1 ]; then
  "$nusselt" render "${small[@]}" --traversal rayquery -o "$work/rq.exr" 2>"$work/rq.err" || fail "rayquery render exit $?"
  [ "$(attr "$work/rq.exr" traversal)" = rayquery ] || fail "rayquery: header traversal '$(attr "$work/rq.exr" traversal)'"
  grep -q "acceleration structures" "$work/rq.err" || fail "rayquery: no acceleration structures in the summary"
  # Resuming with the other traversal works and says it is not bit-identical.
  "$nusselt" render "${small[@]}" --spp 3 --traversal bvh --resume "$work/rq.exr" -o "$work/rq3.exr" 2>"$work/resume.err" ||
    fail "resume with the other traversal: exit $?: $(cat "$work/resume.err")"
  grep -q "traced with --traversal rayquery" "$work/resume.err" || fail "resume: no warning: $(cat "$work/resume.err")"
else
  echo "note: device 0 has no ray queries; rayquery renders not tried"
fi

# No ray queries: auto falls back, rayquery is refused with a message and exit status 1.
NUSSELT_FAULT_NO_RAY_QUERY=1 "$nusselt" render "${small[@]}" -o "$work/fb.exr" -q || fail "fallback render exit $?"
[ "$(attr "$work/fb.exr" traversal)" = bvh ] || fail "fallback: header traversal '$(attr "$work/fb.exr" traversal)'"
NUSSELT_FAULT_NO_RAY_QUERY=1 "$nusselt" render "${small[@]}" --traversal rayquery -o "$work/no.exr" 2>"$work/no.err"
status=$?
[ $status -eq 1 ] || fail "rayquery without ray queries: exit $status (want 1)"
grep -q "does not offer ray queries" "$work/no.err" || fail "rayquery without ray queries: message '$(cat "$work/no.err")'"
[ ! -e "$work/no.exr" ] || fail "rayquery without ray queries wrote an image"
NUSSELT_FAULT_NO_RAY_QUERY=1 "$nusselt" devices | grep -q "no ray queries" || fail "devices under the fault"

"$nusselt" render "${small[@]}" --traversal sideways -o "$work/x.exr" 2>/dev/null
[ $? -eq 2 ] || fail "--traversal sideways: want exit 2"

"$nusselt" bench render --spp 1 --width 16 --height 16 --traversal bvh,auto --repeats 2 "" >"$work/bench" 2>&1 ||
  fail "bench render exit $?: $(cat "$work/bench")"
grep -q "(cornell-box), bvh, median \[min-max\] of 2" "$work/bench" || fail "bench render: no medians: $(cat "$work/bench")"

[ $fails -eq 0 ] && echo "traversal checks pass"
exit $((fails > 0))
