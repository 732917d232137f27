#!/usr/bin/env bash
# --integrator: path is the default and leaves the header as before (no nusselt/integratorName);
# an unknown name and the combinations Metropolis and VEGAS renders do not support are refused with a
# message that says why, a failure status and no output file.
# Usage: integrator.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
small=(--width 8 --height 8 --spp 1 -q --checkpoint 0)

# expect_error NAME EXPECTED_TEXT -- ARGS...
expect_error() {
  local name=$1 expected=$2; shift 3
  "$nusselt" render -o "$work/$name.exr" "${small[@]}" "$@" >"$work/out" 2>"$work/err"
  local status=$?
  if [ $status -eq 0 ] || [ $status -ge 128 ]; then fail "$name: exit status $status"; return; fi
  if [ -e "$work/$name.exr" ]; then fail "$name: wrote an image"; return; fi
  grep -qF -- "$expected" "$work/err" || { fail "$name: message lacks '$expected': $(cat "$work/err")"; return; }
  echo "ok   $name: $(cat "$work/err")"
}

"$nusselt" render -o "$work/path.exr" "${small[@]}" || fail "default render"
"$nusselt" render -o "$work/path2.exr" "${small[@]}" --integrator path || fail "--integrator path"
line=$("$nusselt" diff "$work/path2.exr" "$work/path.exr")
[[ "$line" == *"max |diff| 0" ]] || fail "--integrator path differs from the default: $line"
if "$nusselt" info "$work/path.exr" | grep -q "integratorName"; then fail "a path render's header names its integrator"; fi

expect_error unknown "unknown integrator" -- --integrator bdpt
expect_error mlt_guiding "not supported" -- --integrator mlt --guiding on
expect_error mlt_variance "no per-sample variance" -- --integrator mlt --variance

# An mlt render: its header names it; merging it is refused; resuming it with path is refused,
# with mlt it continues (the chains restart: docs/mlt.md) to the new spp.
"$nusselt" render -o "$work/mlt.exr" "${small[@]}" --integrator mlt --mlt-chains 1024 --spp 2 || fail "mlt render"
[ "$("$nusselt" info "$work/mlt.exr" | sed -n 's/^  nusselt\/integratorName: //p')" = mlt ] || fail "mlt header"
"$nusselt" render -o "$work/mlt2.exr" "${small[@]}" --integrator mlt --mlt-chains 1024 --spp 2 --spp-offset 2 || fail "mlt render 2"
if "$nusselt" merge "$work/mlt.exr" "$work/mlt2.exr" -o "$work/merged.exr" 2>"$work/err"; then fail "merge of mlt renders"
elif ! grep -qF "merging Metropolis renders is not supported" "$work/err"; then fail "merge message: $(cat "$work/err")"
else echo "ok   mlt_merge: $(cat "$work/err")"; fi
cp "$work/mlt.exr" "$work/resume.exr"
if "$nusselt" render "${small[@]}" --resume "$work/resume.exr" --spp 4 2>"$work/err"; then fail "path resume of an mlt render"
elif ! grep -qF "integrator" "$work/err"; then fail "resume message: $(cat "$work/err")"
else echo "ok   mlt_resume_as_path: $(cat "$work/err")"; fi
# The light outside the chains is recorded (the defaults: caustic chains, 1 path-traced sample per
# pixel per 8 steps) and resuming with another split or step count is refused.
[ "$("$nusselt" info "$work/resume.exr" | sed -n 's/^  nusselt\/mltPassSpp: //p')" = 1 ] || fail "mlt header: mltPassSpp"
[ "$("$nusselt" info "$work/resume.exr" | sed -n 's/^  nusselt\/mltChainLight: //p')" = caustic ] || fail "mlt header: mltChainLight"
[ "$("$nusselt" info "$work/resume.exr" | sed -n 's/^  nusselt\/mltSteps: //p')" = 8 ] || fail "mlt header: mltSteps"
for other in "--mlt-direct-spp 0" "--mlt-pass-spp 2" "--mlt-chain-light indirect" "--mlt-steps 4"; do
  # shellcheck disable=SC2086
  if "$nusselt" render "${small[@]}" --integrator mlt --mlt-chains 1024 $other --resume "$work/resume.exr" \
    --spp 4 2>"$work/err"; then fail "mlt resume with $other"
  elif ! grep -qF -- "--mlt-chain-light, --mlt-pass-spp, --mlt-steps" "$work/err"; then fail "resume message: $(cat "$work/err")"
  else echo "ok   mlt_resume_with $other: $(cat "$work/err")"; fi
done
expect_error mlt_chain_light "--mlt-chain-light" -- --integrator mlt --mlt-chain-light direct
expect_error mlt_steps "--mlt-steps" -- --integrator mlt --mlt-steps 0
# Restarts: auto resolves to a bootstrap pool's worth of samples per pixel (2^21 / 64 pixels); a
# word that is none of auto, off or a number, and restarts of chains without a caustic pass, are
# refused.
[ "$("$nusselt" info "$work/mlt.exr" | sed -n 's/^  nusselt\/mltRestart: //p')" = 32768 ] || fail "mlt header: mltRestart"
expect_error mlt_restart_word "--mlt-restart often" -- --integrator mlt --mlt-restart often
expect_error mlt_restart_negative "--mlt-restart -3" -- --integrator mlt --mlt-restart -3
expect_error mlt_restart_indirect "--mlt-restart needs" -- --integrator mlt --mlt-chain-light indirect --mlt-restart 4
"$nusselt" render "${small[@]}" --integrator mlt --mlt-chains 1024 --resume "$work/resume.exr" --spp 4 \
  || fail "mlt resume"
[ "$("$nusselt" info "$work/resume.exr" | sed -n 's/^  nusselt\/spp: //p')" = 4 ] || fail "mlt resume: spp in the header"

# vegas: bad options and unsupported combinations are refused; its header names it and its
# options; merging it and resuming it as path are refused; resumed as vegas it continues (its tables
# learned anew: docs/vegas.md).
expect_error vegas_bins "--vegas-bins 0: between 1 and 4096" -- --integrator vegas --vegas-bins 0
expect_error vegas_bounces "--vegas-bounces 0" -- --integrator vegas --vegas-bounces 0
expect_error vegas_bounces_depth "max depth + 1" -- --integrator vegas --vegas-bounces 4 --max-depth 2
expect_error vegas_alpha "--vegas-alpha" -- --integrator vegas --vegas-alpha 0
expect_error vegas_guiding "not supported" -- --integrator vegas --guiding on
"$nusselt" render -o "$work/vegas.exr" "${small[@]}" --integrator vegas --spp 4 --samples-per-pass 2 --vegas-bins 16 \
  --variance || fail "vegas render"
[ "$("$nusselt" info "$work/vegas.exr" | sed -n 's/^  nusselt\/integratorName: //p')" = vegas ] || fail "vegas header"
[ "$("$nusselt" info "$work/vegas.exr" | sed -n 's/^  nusselt\/vegasBins: //p')" = 16 ] || fail "vegas bins in the header"
"$nusselt" render -o "$work/vegas2.exr" "${small[@]}" --integrator vegas --spp 2 --spp-offset 4 || fail "vegas render 2"
if "$nusselt" merge "$work/vegas.exr" "$work/vegas2.exr" -o "$work/merged.exr" 2>"$work/err"; then fail "merge of vegas renders"
elif ! grep -qF "merging VEGAS renders is not supported" "$work/err"; then fail "merge message: $(cat "$work/err")"
else echo "ok   vegas_merge: $(cat "$work/err")"; fi
if "$nusselt" merge "$work/path.exr" "$work/vegas2.exr" -o "$work/merged.exr" 2>"$work/err"; then fail "merge of path and vegas"
else echo "ok   vegas_merge_with_path: $(cat "$work/err")"; fi
cp "$work/vegas.exr" "$work/resume.exr"
if "$nusselt" render "${small[@]}" --resume "$work/resume.exr" --spp 8 2>"$work/err"; then fail "path resume of a vegas render"
elif ! grep -qF "integrator" "$work/err"; then fail "resume message: $(cat "$work/err")"
else echo "ok   vegas_resume_as_path: $(cat "$work/err")"; fi
"$nusselt" render "${small[@]}" --integrator vegas --samples-per-pass 2 --vegas-bins 16 --variance \
  --resume "$work/resume.exr" --spp 8 || fail "vegas resume"
[ "$("$nusselt" info "$work/resume.exr" | sed -n 's/^  nusselt\/spp: //p')" = 8 ] || fail "vegas resume: spp in the header"

[ $fails -eq 0 ] && echo "all integrator checks passed"
exit $((fails > 0))
