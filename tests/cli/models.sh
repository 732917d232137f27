#!/usr/bin/env bash
# `nusselt models` lists every model of the list in shaders/shared/brdf/models.h, once, by id;
# docs/models.md carries what `nusselt models --markdown` prints for each model (its heading,
# summary and parameter table: the page is regenerated from the program, so this checks that
# docs and code agree); an unknown option is a usage error.
# Usage: models.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

"$nusselt" models >"$work/list" || fail "models exit $?"
count=$(grep -c '^  X([0-9]*u, ' "$src/shaders/shared/brdf/models.h")
listed=$(grep -c '^[a-z_0-9]* *id *[0-9]*' "$work/list")
[ "$count" -ge 21 ] && [ "$listed" = "$count" ] && echo "ok   $listed models listed (the list has $count)" ||
  fail "models listed $listed, the list in models.h has $count"
for ((id = 0; id < count; ++id)); do
  grep -q "^[a-z_0-9]* *id *$id[:,]" "$work/list" || fail "model id $id not listed"
done

"$nusselt" models --markdown >"$work/md" || fail "models --markdown exit $?"
missing=0
while IFS= read -r line; do
  [ -z "$line" ] && continue
  grep -qxF -- "$line" "$src/docs/models.md" || { missing=$((missing + 1)); [ $missing -le 5 ] && echo "  not in docs/models.md: $line"; }
done <"$work/md"
[ $missing = 0 ] && echo "ok   docs/models.md carries every line of models --markdown" ||
  fail "$missing lines of models --markdown are not in docs/models.md (regenerate its tables)"

"$nusselt" models --no-such-option >/dev/null 2>&1
[ $? = 2 ] && echo "ok   an unknown option is a usage error (exit 2)" || fail "unknown option: exit not 2"

[ $fails = 0 ]
