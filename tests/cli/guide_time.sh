#!/usr/bin/env bash
# Guided renders with a time budget (docs/guiding.md, "Training within a time budget"): the
# automatic training ends at the end of an iteration when the next one would leave less than twice
# its own time; the record states the spp actually trained, so a resumed render retrains exactly those
# (no guide-hash warning). A training spp asked for with --guide-train is kept as asked.
# Usage: guide_time.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
header() { "$nusselt" info "$1" | awk -v k="nusselt/$2:" '$1 == k {print $2}'; }
scene=$src/scenes/cornell/cornell-indirect.glb
# 256 x 256: the automatic 127 training spp take about 15 s on lavapipe on 2 cores, far above the 3 s.
common=(--width 256 --height 256 --max-depth 4 --seed 5 --guiding on --guide-alpha 0.5 --checkpoint 0)
# Untimed first: lavapipe compiles a pipeline at its first dispatch (Mesa's disk cache keeps it),
# which on a cold cache could take the whole budget before the first iteration ends.
"$nusselt" render "$scene" "${common[@]}" --width 16 --height 16 --spp 2 -q -o "$work/warm.exr" || fail "warm-up render"

"$nusselt" render "$scene" "${common[@]}" --time 3 --spp 100000 -o "$work/t.exr" 2>"$work/t.err" ||
  fail "timed render exit $?: $(cat "$work/t.err")"
trained=$(header "$work/t.exr" guideTrainSpp)
spp=$(header "$work/t.exr" spp)
case "$trained" in
  3 | 7 | 15 | 31 | 63) echo "ok   training ended at $trained spp (an iteration's end), $spp spp in all" ;;
  *) fail "guideTrainSpp '$trained' is not the end of an iteration below 127" ;;
esac
[ -n "$spp" ] && [ -n "$trained" ] && [ "$spp" -gt "$trained" ] || fail "no sample after the training ($spp spp, $trained trained)"
grep -q "^guiding: $trained training spp (ended by the time budget" "$work/t.err" ||
  fail "no message of the ended training: $(grep '^guiding: [0-9]* training' "$work/t.err")"

# Resumed: the retraining covers the recorded spp, so the guide's hash matches (no warning).
"$nusselt" render "$scene" "${common[@]}" --spp $((spp + 4)) --resume "$work/t.exr" -o "$work/r.exr" 2>"$work/r.err" ||
  fail "resume exit $?: $(cat "$work/r.err")"
grep -q "warning" "$work/r.err" && fail "resume warns: $(grep warning "$work/r.err")"
[ "$(header "$work/r.exr" guideTrainSpp)" = "$trained" ] || fail "resumed guideTrainSpp $(header "$work/r.exr" guideTrainSpp), not $trained"
[ "$(header "$work/r.exr" spp)" = $((spp + 4)) ] || fail "resumed spp $(header "$work/r.exr" spp), not $((spp + 4))"

# An asked-for training spp is kept (the budget may still stop the render during it).
"$nusselt" render "$scene" "${common[@]}" --time 1 --spp 100000 --guide-train 63 -o "$work/a.exr" 2>"$work/a.err" ||
  fail "render with --guide-train exit $?: $(cat "$work/a.err")"
[ "$(header "$work/a.exr" guideTrainSpp)" = 63 ] || fail "--guide-train 63 recorded as $(header "$work/a.exr" guideTrainSpp)"
grep -q "ended by the time budget" "$work/a.err" && fail "--guide-train 63: the budget ended the asked-for training"

[ $fails -eq 0 ] && echo "guide_time: ok"
exit $((fails > 0))
