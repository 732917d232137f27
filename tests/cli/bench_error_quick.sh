#!/usr/bin/env bash
# `nusselt bench error --quick` runs both experiments and writes its outputs, and every estimator
# agrees with its reference: at one shading point each strategy's mean of all its samples lies within
# its Bonferroni confidence interval of the quadrature reference (point_summary.csv, column agree),
# and in the scenes each render's image mean agrees with the high-spp reference's (scenes.csv,
# column agree). It is a benchmark: it checks that the experiments run and the estimators agree,
# not that any strategy reaches a given error.
# The report is made from the CSV files alone: `--report-from` on the run's directory must give its
# results.md byte for byte, its headline count must equal one computed here from
# point_summary.csv, its links into docs/results-method.md must name headings there, and a missing
# or malformed CSV file must stop it with an error naming the file.
# Usage: bench_error_quick.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
source_dir=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

"$nusselt" bench error --quick --out "$work/out" >"$work/stdout" 2>"$work/stderr"
status=$?
[ $status -eq 0 ] || { fail "bench error --quick exit $status: $(tail -5 "$work/stderr")"; exit 1; }
cat "$work/stdout"
for f in run.csv point.csv point_summary.csv scenes.csv results.md; do
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
grep -q "^rng,cornell,pcg," "$work/out/scenes.csv" || fail "no PCG row"
grep -q "^components,cornell-combined,uniform," "$work/out/scenes.csv" || fail "no uniform component-choice row"

# The report: summary first, one table per family of the quick run's models.
report=$work/out/results.md
summary=$(grep -n "^## Summary" "$report" | cut -d: -f1)
exp1=$(grep -n "^## Experiment 1" "$report" | cut -d: -f1)
[ -n "$summary" ] && [ -n "$exp1" ] && [ "$summary" -lt "$exp1" ] || fail "results.md: no summary before experiment 1"
for fam in "Phong-like lobes" "Microfacet and physically based" "Other empirical"; do
  grep -q "^### $fam\$" "$report" || fail "results.md: no table for the family $fam"
done
# The headline, counted independently: environment cases (model, preset, angle) where the quadtree's
# time to 1e-3 is strictly below every other strategy's (ties go to the first in the file's order,
# which is the quadtree's).
read -r wins cases < <(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  $c["integrand"] == "env" { k = $c["model"] "," $c["preset"] "," $c["theta"]
    t = $c["t_1e-3"] ~ /^[0-9.eE+-]+$/ ? $c["t_1e-3"] + 0 : 1e308  # inf, nan: never reached
    if (!(k in best) || t < best[k]) { best[k] = t; who[k] = $c["strategy"] } }
  END { n = 0; w = 0; for (k in who) { n++; if (who[k] == "quadtree") w++ } print w, n }' "$work/out/point_summary.csv")
grep -q "The quadtree is the fastest strategy in $wins of $cases cases" "$report" ||
  fail "results.md: headline does not say $wins of $cases cases: $(grep -m1 'fastest strategy in' "$report")"
# Every link into docs/results-method.md names a heading there.
for anchor in $(grep -o 'results-method\.md#[a-z-]*' "$report" | cut -d'#' -f2 | sort -u); do
  grep -qix "#\+ ${anchor//-/ }" "$source_dir/docs/results-method.md" ||
    fail "results.md links results-method.md#$anchor, which is no heading of docs/results-method.md"
done

# --report-from: the same bytes from the CSV files alone.
"$nusselt" bench error --report-from "$work/out" --report "$work/again.md" >"$work/rf.out" 2>&1 ||
  fail "--report-from exit $?: $(cat "$work/rf.out")"
cmp -s "$report" "$work/again.md" || { fail "--report-from differs from the run's results.md:"; diff "$report" "$work/again.md" | head -20; }
# A missing or malformed CSV file: a non-zero exit and an error naming the file.
broken() {  # broken NAME FILE EDIT: copy the CSV files, apply EDIT (a sed script) to FILE, or delete it
  local dir=$work/$1
  mkdir -p "$dir" && cp "$work/out"/*.csv "$dir"/
  if [ "$3" = delete ]; then rm "$dir/$2"; else sed -i "$3" "$dir/$2"; fi
  if "$nusselt" bench error --report-from "$dir" --report "$dir/r.md" >"$dir/out" 2>&1; then
    fail "--report-from with $1 $2 succeeded"
  elif ! grep -q "$dir/$2" "$dir/out"; then
    fail "--report-from with $1 $2: the error does not name the file: $(cat "$dir/out")"
  fi
}
broken missing point_summary.csv delete
broken missing run.csv delete
broken short scenes.csv '3s/,[^,]*$//'
broken nonnumeric point_summary.csv '2s/^\([^,]*,[^,]*,\)[^,]*/\1abc/'
[ $fails -eq 0 ] && echo "bench error --quick: outputs present, all estimators agree"
exit $((fails > 0))
