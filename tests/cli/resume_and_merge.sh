#!/usr/bin/env bash
# Renders that lose nothing: --resume continues bit-exactly; --spp-offset splits a frame and
# `nusselt merge` combines the parts into the single render of the same samples.
# Usage: resume_and_merge.sh NUSSELT SOURCE_DIR
set -u
nusselt=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
common=(--width 24 --height 16 --seed 3 --max-depth 4 -q)
maxdiff() { "$nusselt" diff "$1" "$2" | sed -n 's/.*max |diff| //p'; }
# expect_refused WHAT PATTERN COMMAND...: the command must fail with PATTERN in its error output.
expect_refused() {
  local what=$1 pattern=$2
  shift 2
  if "$@" 2>"$work/err"; then
    fail "$what accepted"
  else
    grep -q -- "$pattern" "$work/err" && echo "ok   $what refused: $(cat "$work/err")" || fail "$what refusal: $(cat "$work/err")"
  fi
}

"$nusselt" render "${common[@]}" --spp 6 -o "$work/full.exr" || fail "full render"

# Resume: 2 spp, then on to 6: identical pixels to the uninterrupted 6-spp render.
"$nusselt" render "${common[@]}" --spp 2 -o "$work/part.exr" || fail "partial render"
"$nusselt" render "${common[@]}" --spp 6 --resume "$work/part.exr" || fail "resume"
[ "$("$nusselt" info "$work/part.exr" | sed -n 's/^  nusselt\/spp: //p')" = 6 ] || fail "resumed spp"
[ "$(maxdiff "$work/part.exr" "$work/full.exr")" = 0 ] && echo "ok   resumed 2 -> 6 spp equals 6 spp bit for bit" ||
  fail "resumed render differs: $("$nusselt" diff "$work/part.exr" "$work/full.exr")"

# Resuming with other settings is refused, and the file is left as it was.
cp "$work/part.exr" "$work/keep.exr"
if "$nusselt" render --width 24 --height 16 --seed 4 --max-depth 4 -q --spp 8 --resume "$work/part.exr" 2>"$work/err"; then
  fail "resume with another seed was accepted"
else
  grep -q "seed" "$work/err" && cmp -s "$work/part.exr" "$work/keep.exr" && echo "ok   resume with another seed refused: $(cat "$work/err")" ||
    fail "resume refusal: $(cat "$work/err")"
fi

# An interrupted render resumes to the same image as an uninterrupted one.
"$nusselt" render "${common[@]}" --spp 1000000 --checkpoint 1 -o "$work/int.exr" &
pid=$!
# Interrupt once the render loop runs (its first checkpoint exists: setup time varies with the
# load), after a few more passes.
for _ in $(seq 600); do [ -s "$work/int.exr" ] && break; sleep 0.5; done
sleep 1
kill -INT $pid
wait $pid
k=$("$nusselt" info "$work/int.exr" 2>/dev/null | sed -n 's/^  nusselt\/spp: //p')
if [ -n "$k" ] && [ "$k" -ge 1 ]; then
  total=$((k + 3))
  "$nusselt" render "${common[@]}" --spp $total --resume "$work/int.exr" || fail "resume after SIGINT"
  "$nusselt" render "${common[@]}" --spp $total -o "$work/straight.exr" || fail "straight render"
  [ "$(maxdiff "$work/int.exr" "$work/straight.exr")" = 0 ] && echo "ok   interrupted at $k spp, resumed to $total: identical" ||
    fail "interrupted+resumed differs: $("$nusselt" diff "$work/int.exr" "$work/straight.exr")"
else
  fail "interrupted render wrote no spp"
fi

# A guided render (docs/guiding.md, "Resume") resumes bit-exactly too: the resumed run trains its
# guide again on the saved render's first samples and checks the guide's hash in the header. Saved
# inside training at an iteration's end (3 spp), inside an iteration (5), and after training (9).
# A fixed --guide-alpha makes the guide sample everywhere (auto may leave it unused here).
guided=(--guiding on --guide-train 7 --guide-alpha 0.5)
"$nusselt" render "${common[@]}" "${guided[@]}" --spp 12 -o "$work/gfull.exr" || fail "guided render"
for k in 3 5 9; do
  "$nusselt" render "${common[@]}" "${guided[@]}" --spp $k -o "$work/g$k.exr" || fail "guided render of $k spp"
  "$nusselt" render --width 24 --height 16 --seed 3 --max-depth 4 "${guided[@]}" --spp 12 --resume "$work/g$k.exr" \
    2>"$work/err" || fail "guided resume from $k spp: $(cat "$work/err")"
  grep -q "warning" "$work/err" && fail "guided resume from $k spp warns: $(grep warning "$work/err")"
  [ "$(maxdiff "$work/g$k.exr" "$work/gfull.exr")" = 0 ] && echo "ok   guided, resumed $k -> 12 spp equals 12 spp bit for bit" ||
    fail "guided resume from $k spp differs: $("$nusselt" diff "$work/g$k.exr" "$work/gfull.exr")"
done
# Its guide settings must be the saved render's.
"$nusselt" render "${common[@]}" "${guided[@]}" --spp 3 -o "$work/g3.exr" || fail "guided render of 3 spp"
expect_refused "guided resume with another --guide-alpha" "--guide-alpha was 0.5" \
  "$nusselt" render "${common[@]}" --guiding on --guide-train 7 --guide-alpha 0.25 --spp 12 --resume "$work/g3.exr"
expect_refused "guided resume with another --guide-learn" "--guide-learn was product" \
  "$nusselt" render "${common[@]}" "${guided[@]}" --guide-learn radiance --spp 12 --resume "$work/g3.exr"

# With the photon pre-pass (--guide-photons): the resumed run traces the same photons again before
# its retraining; a resume with another photon count is refused.
photons=(--guiding on --guide-train 7 --guide-alpha 0.5 --guide-photons 3000)
"$nusselt" render "${common[@]}" "${photons[@]}" --spp 12 -o "$work/pfull.exr" || fail "render with photons"
"$nusselt" render "${common[@]}" "${photons[@]}" --spp 5 -o "$work/p5.exr" || fail "render with photons of 5 spp"
[ "$(maxdiff "$work/pfull.exr" "$work/gfull.exr")" != 0 ] || fail "the photons did not change the guided render"
"$nusselt" render --width 24 --height 16 --seed 3 --max-depth 4 "${photons[@]}" --spp 12 --resume "$work/p5.exr" \
  2>"$work/err" || fail "resume with photons: $(cat "$work/err")"
grep -q "warning" "$work/err" && fail "resume with photons warns: $(grep warning "$work/err")"
[ "$(maxdiff "$work/p5.exr" "$work/pfull.exr")" = 0 ] && echo "ok   guided with photons, resumed 5 -> 12 spp equals 12 spp bit for bit" ||
  fail "resume with photons differs: $("$nusselt" diff "$work/p5.exr" "$work/pfull.exr")"
"$nusselt" render "${common[@]}" "${photons[@]}" --spp 3 -o "$work/p3.exr" || fail "render with photons of 3 spp"
expect_refused "resume with another --guide-photons" "--guide-photons was 3000" \
  "$nusselt" render "${common[@]}" --guiding on --guide-train 7 --guide-alpha 0.5 --spp 12 --resume "$work/p3.exr"

# Split across two jobs by --spp-offset, merged: the single 6-spp render up to float rounding
# of the sums (the parts add their sums in another order).
"$nusselt" render "${common[@]}" --spp 3 --spp-offset 0 -o "$work/a.exr" || fail "job a"
"$nusselt" render "${common[@]}" --spp 3 --spp-offset 3 -o "$work/b.exr" || fail "job b"
"$nusselt" merge "$work/a.exr" "$work/b.exr" -o "$work/merged.exr" 2>/dev/null || fail "merge"
d=$(maxdiff "$work/merged.exr" "$work/full.exr")
mean=$("$nusselt" diff "$work/merged.exr" "$work/full.exr" | sed -n 's/.*mean \([^ ]*\) .*/\1/p')
# Float rounding of a 6-term sum: a few ulps of the largest values (radiance up to ~20 here).
awk -v d="$d" 'BEGIN { exit !(d <= 2e-5 * 20) }' && echo "ok   merged offsets 0+3 equal the 6-spp render (max |diff| $d)" ||
  fail "merged image differs: max |diff| $d"
[ "$("$nusselt" info "$work/merged.exr" | sed -n 's/^  nusselt\/spp: //p')" = 6 ] || fail "merged spp"

# Overlapping sample ranges are refused.
if "$nusselt" merge "$work/a.exr" "$work/a.exr" -o "$work/bad.exr" 2>"$work/err"; then
  fail "overlapping merge accepted"
else
  grep -q overlap "$work/err" && [ ! -e "$work/bad.exr" ] && echo "ok   overlapping ranges refused" || fail "overlap message: $(cat "$work/err")"
fi

# A crash (SIGKILL: no handler runs) loses at most one checkpoint interval: the output holds a
# resumable image.
"$nusselt" render "${common[@]}" --spp 1000000 --checkpoint 1 -o "$work/crash.exr" 2>/dev/null &
pid=$!
# Kill once the first checkpoint exists (setup time varies with the load).
for _ in $(seq 600); do [ -s "$work/crash.exr" ] && break; sleep 0.5; done
sleep 0.5
kill -KILL $pid
wait $pid 2>/dev/null
k=$("$nusselt" info "$work/crash.exr" 2>/dev/null | sed -n 's/^  nusselt\/spp: //p')
if [ -n "$k" ] && [ "$k" -ge 1 ] && [ "$("$nusselt" info "$work/crash.exr" | sed -n 's/^  nusselt\/checkpoint: //p')" = 1 ]; then
  "$nusselt" render "${common[@]}" --spp $((k + 2)) --resume "$work/crash.exr" || fail "resume after a crash"
  "$nusselt" render "${common[@]}" --spp $((k + 2)) -o "$work/crash_ref.exr" || fail "reference render"
  [ "$(maxdiff "$work/crash.exr" "$work/crash_ref.exr")" = 0 ] && echo "ok   killed at checkpoint $k spp, resumed: identical" ||
    fail "resumed-after-crash differs"
else
  fail "no checkpoint after a crash (spp '$k')"
fi

# A lost device: a clear error naming the last checkpoint, non-zero exit, and the checkpoint
# resumes (fault injection: the device "is lost" after 1500 samples, checkpoints every 0.2 s).
if NUSSELT_FAULT_DEVICE_LOST_AFTER=1500 "$nusselt" render "${common[@]}" --spp 3000 --checkpoint 0.2 -o "$work/lost.exr" 2>"$work/err"; then
  fail "device loss not reported"
else
  k=$("$nusselt" info "$work/lost.exr" 2>/dev/null | sed -n 's/^  nusselt\/spp: //p')
  # The loss strikes at the first pass boundary at or past 1500 spp (a pass holds several
  # samples), so the checkpoint may lie past 1500 too, never past the loss.
  lostat=$(sed -n 's/.*device was lost .* after \([0-9]*\) spp.*/\1/p' "$work/err")
  named=$(sed -n 's/.*last checkpoint (\([0-9]*\) spp).*/\1/p' "$work/err")
  if grep -q "VK_ERROR_DEVICE_LOST" "$work/err" && grep -q -- "--resume" "$work/err" && [ -n "$k" ] &&
    [ -n "$lostat" ] && [ "$lostat" -ge 1500 ] && [ "$k" -ge 1 ] && [ "$k" -le "$lostat" ] && [ "$named" = "$k" ]; then
    echo "ok   device lost: $(cat "$work/err")"
    "$nusselt" render "${common[@]}" --spp 1600 --resume "$work/lost.exr" || fail "resume after device loss"
  else
    fail "device loss message or checkpoint: $(cat "$work/err") (checkpoint spp '$k')"
  fi
fi

# A full disk gives a clear error, a non-zero exit, and the previous file intact. The disk is a
# small tmpfs, filled up, in a private mount namespace (unshare: root, or unprivileged user
# namespaces), so nothing else is touched. A file-size limit (ulimit -f) would also stop the
# driver: lavapipe (Mesa 25) backs device memory with files and dies of SIGBUS past the limit.
cp "$work/full.exr" "$work/keep2.exr"
mkdir "$work/disk"
export nusselt work
disk_script='
  mount -t tmpfs -o size=1m tmpfs "$work/disk" || exit 90
  cp "$work/keep2.exr" "$work/disk/full.exr"
  dd if=/dev/zero of="$work/disk/filler" bs=4k 2>/dev/null
  "$nusselt" render --width 24 --height 16 --seed 3 --max-depth 4 -q --spp 2 -o "$work/disk/full.exr" 2>"$work/err"
  echo $? > "$work/rc"
  cmp -s "$work/disk/full.exr" "$work/keep2.exr" && echo same > "$work/cmp"
  ls -a "$work/disk" > "$work/ls"'
if unshare -m sh -c "$disk_script" 2>/dev/null || unshare -rm sh -c "$disk_script" 2>/dev/null ||
   [ -s "$work/rc" ]; then
  rc=$(cat "$work/rc")
  if [ "$rc" != 0 ] && [ "$rc" != 139 ] && [ "$rc" != 135 ] && grep -q "full.exr" "$work/err" &&
     [ "$(cat "$work/cmp" 2>/dev/null)" = same ] && ! grep -q "tmp" "$work/ls"; then
    echo "ok   full disk: exit $rc: $(cat "$work/err")"
  else
    fail "full disk: exit $rc, previous file $(cat "$work/cmp" 2>/dev/null || echo changed), files: $(tr '\n' ' ' < "$work/ls"): $(cat "$work/err")"
  fi
else
  echo "skip full disk: no mount namespace available here (unshare -m needs root or user namespaces)"
fi

[ $fails -eq 0 ] && echo "resume and merge checks pass"
exit $((fails > 0))
