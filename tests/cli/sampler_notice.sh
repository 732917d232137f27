#!/usr/bin/env bash
# The quadtree build notice: a render whose materials' trees are not in the cache says so before
# building them (a first build can take minutes); a render that builds nothing (trees in the
# cache, or only constant BRDFs, which cosine samples) does not; --quiet silences it.
# Usage: sampler_notice.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export NUSSELT_CACHE_DIR=$work/cache
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
small=(--width 8 --height 8 --spp 1 --max-depth 2)
glossy=$src/scenes/cornell/cornell-glossy.glb

"$nusselt" render "$glossy" "${small[@]}" -o "$work/a.exr" 2>"$work/a.err" || fail "cold render exit $?: $(cat "$work/a.err")"
grep -q "^sampler: building the quadtrees of 1 material (90 tables; cached in $work/cache" "$work/a.err" ||
  fail "cold cache: no build notice: $(cat "$work/a.err")"
# The notice comes before the work it announces (the summary that follows reports it).
n=$(grep -n "^sampler: building" "$work/a.err" | cut -d: -f1)
s=$(grep -n "1 built" "$work/a.err" | cut -d: -f1)
[ -n "$n" ] && [ -n "$s" ] && [ "$n" -lt "$s" ] || fail "notice (line $n) not before the build summary (line $s)"

"$nusselt" render "$glossy" "${small[@]}" -o "$work/b.exr" 2>"$work/b.err" || fail "warm render exit $?"
grep -q "1 hits, 0 built" "$work/b.err" || fail "warm cache: not a cache hit: $(cat "$work/b.err")"
grep -q "building" "$work/b.err" && fail "warm cache: a build notice without a build: $(cat "$work/b.err")"

"$nusselt" render "${small[@]}" -o "$work/c.exr" 2>"$work/c.err" || fail "default scene exit $?"
grep -q "building" "$work/c.err" && fail "constant BRDFs only: a build notice: $(cat "$work/c.err")"

rm -rf "$work/cache"
"$nusselt" render "$glossy" "${small[@]}" --quiet -o "$work/d.exr" 2>"$work/d.err" || fail "quiet render exit $?"
[ -s "$work/d.err" ] && fail "--quiet printed: $(cat "$work/d.err")"

[ $fails -eq 0 ] && echo "sampler_notice: ok"
exit $((fails > 0))
