#!/usr/bin/env bash
# `nusselt bench error --quick` runs both experiments and writes its outputs, and every estimator
# agrees with its reference: at one shading point each strategy's mean of all its samples lies within
# its Bonferroni confidence interval of the quadrature reference (point_summary.csv, column agree),
# and in the scenes each render's image mean agrees with the high-spp reference's (scenes.csv,
# column agree). It is a benchmark: it checks that the experiments run and the estimators agree,
# not that any strategy reaches a given error.
# Usage: bench_error_quick.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

"$nusselt" bench error --quick --out "$work/out" >"$work/stdout" 2>"$work/stderr"
status=$?
[ $status -eq 0 ] || { fail "bench error --quick exit $status: $(tail -5 "$work/stderr")"; exit 1; }
cat "$work/stdout"
for f in point.csv point_summary.csv scenes.csv results.md; do
  [ -s "$work/out/$f" ] || fail "missing or empty $f"
done
ls "$work/out"/point-*.png >/dev/null 2>&1 || fail "no point plots"
ls "$work/out"/scene-*.png >/dev/null 2>&1 || fail "no scene images"
# Five strategies, two integrands per model/preset/angle; every row agrees.
rows=$(tail -n +2 "$work/out/point_summary.csv" | wc -l)
[ "$rows" -ge 10 ] || fail "point_summary.csv has $rows rows"
for s in quadtree tabulated analytic cosine uniform; do
  grep -q ",$s," "$work/out/point_summary.csv" || fail "no $s rows in point_summary.csv"
  grep -q "^strategies,.*,$s," "$work/out/scenes.csv" || fail "no $s render in scenes.csv"
done
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "agree") c = i; next }
         $c != 1 { print "point estimate disagrees: " $0; bad = 1 } END { exit bad }' "$work/out/point_summary.csv" ||
  fail "point estimates disagree with their references"
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "agree") c = i; next }
         $c != 1 { print "render disagrees: " $0; bad = 1 } END { exit bad }' "$work/out/scenes.csv" ||
  fail "renders disagree with their references"
grep -qiwE "nan|inf" "$work/out/scenes.csv" && fail "non-finite value in scenes.csv"
grep -q "^rng,cornell,qmc," "$work/out/scenes.csv" || fail "no QMC row"
grep -q "^components,cornell-combined,uniform," "$work/out/scenes.csv" || fail "no uniform component-choice row"
grep -q "time to reach\|t(1e-3)" "$work/out/results.md" || fail "results.md lacks the time-to-error table"
[ $fails -eq 0 ] && echo "bench error --quick: outputs present, all estimators agree"
exit $((fails > 0))
