#!/usr/bin/env bash
# `nusselt preview` (issue 7) under Xvfb: the window shows the same film as a headless render,
# resizing recreates the swapchain without validation messages, an idle window does not spin
# the CPU, and without a display the command fails with a message pointing to `nusselt render`.
# Runs with NUSSELT_VALIDATION=1 (ctest), so any validation message fails a preview run.
# Needs Xvfb (Debian package xvfb) and python3 (standard library only: PNG and XWD decoding).
# Usage: preview.sh NUSSELT SOURCE_DIR
set -u
nusselt=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")  # absolute: one run changes directory
work=$(mktemp -d)
xvfb_pid=
cleanup() {
  [ -n "$xvfb_pid" ] && kill "$xvfb_pid" 2>/dev/null && wait "$xvfb_pid" 2>/dev/null
  rm -rf "$work"
}
trap cleanup EXIT
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
ok() { echo "ok   $*"; }

# ---- No display: a clear message that suggests `nusselt render`, non-zero exit ------------------
(unset DISPLAY WAYLAND_DISPLAY; "$nusselt" preview --frames 1 >"$work/nodisp.out" 2>&1)
status=$?
if [ $status -ne 0 ] && grep -q "nusselt render" "$work/nodisp.out"; then
  ok "no display: exit $status, $(head -c 120 "$work/nodisp.out")..."
else
  fail "no display: exit $status, output: $(cat "$work/nodisp.out")"
fi
# An unreachable display is the same failure.
DISPLAY=:987 "$nusselt" preview --frames 1 >"$work/baddisp.out" 2>&1
status=$?
{ [ $status -ne 0 ] && grep -q "nusselt render" "$work/baddisp.out"; } || fail "display :987: exit $status: $(cat "$work/baddisp.out")"

# `--help` lists the keys.
"$nusselt" preview --help >"$work/help.out" 2>&1 || fail "preview --help exit $?"
for k in "Esc" "orbit" "zoom" "exposure" "quadtree" "cosine" "analytic" "tabulated" "uniform" "save"; do
  grep -qi "$k" "$work/help.out" || fail "--help does not mention '$k'"
done

# ---- An X server for the rest: Xvfb picks a free display and keeps its screen in an XWD file ----
if ! command -v Xvfb >/dev/null; then
  fail "Xvfb not installed (apt-get install xvfb)"
  exit 1
fi
mkdir -p "$work/fb"
Xvfb -displayfd 3 -screen 0 320x240x24 -fbdir "$work/fb" -nolisten tcp 3>"$work/display" 2>"$work/xvfb.log" &
xvfb_pid=$!
for _ in $(seq 100); do [ -s "$work/display" ] && break; sleep 0.1; done
[ -s "$work/display" ] || { fail "Xvfb did not start: $(cat "$work/xvfb.log")"; exit 1; }
export DISPLAY=:$(head -1 "$work/display")
screen=$work/fb/Xvfb_screen0

# Image helpers: PNG (8-bit RGB/RGBA) and the Xvfb XWD screen, standard library only.
cat >"$work/img.py" <<'EOF'
import math, struct, sys, zlib

def png(path):
    d = open(path, 'rb').read()
    assert d[:8] == b'\x89PNG\r\n\x1a\n', path + ': not a PNG'
    i, idat = 8, b''
    while i < len(d):
        n, = struct.unpack('>I', d[i:i + 4]); t = d[i + 4:i + 8]; c = d[i + 8:i + 8 + n]; i += 12 + n
        if t == b'IHDR': w, h, depth, ctype = struct.unpack('>IIBB', c[:10])
        elif t == b'IDAT': idat += c
    assert depth == 8 and ctype in (2, 6), path + ': not 8-bit RGB(A)'
    ch = 3 if ctype == 2 else 4
    raw = zlib.decompress(idat); stride = w * ch; prev = bytearray(stride); p = 0; px = []
    for y in range(h):
        f = raw[p]; line = bytearray(raw[p + 1:p + 1 + stride]); p += 1 + stride
        for x in range(stride):
            a = line[x - ch] if x >= ch else 0; b = prev[x]; c = prev[x - ch] if x >= ch else 0
            if f == 1: line[x] = (line[x] + a) & 255
            elif f == 2: line[x] = (line[x] + b) & 255
            elif f == 3: line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                q = a + b - c; pa, pb, pc = abs(q - a), abs(q - b), abs(q - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        px.append([tuple(line[x * ch:x * ch + 3]) for x in range(w)]); prev = line
    return w, h, px

def xwd(path, x0, y0, w, h):
    d = open(path, 'rb').read()
    hdr = struct.unpack('>25I', d[:100])
    hsize, bpp, bpl, ncolors = hdr[0], hdr[11], hdr[12], hdr[19]
    rmask, gmask, bmask = hdr[14], hdr[15], hdr[16]
    assert bpp == 32, 'XWD: %d bits per pixel' % bpp
    order = '<' if hdr[7] == 0 else '>'
    base = hsize + 12 * ncolors
    sh = lambda m: (m & -m).bit_length() - 1
    px = []
    for y in range(y0, y0 + h):
        row = []
        for x in range(x0, x0 + w):
            v, = struct.unpack(order + 'I', d[base + y * bpl + 4 * x:base + y * bpl + 4 * x + 4])
            row.append(((v & rmask) >> sh(rmask), (v & gmask) >> sh(gmask), (v & bmask) >> sh(bmask)))
        px.append(row)
    return w, h, px

def stats(img):
    w, h, px = img
    v = [c for row in px for p in row for c in p]
    m = sum(v) / len(v)
    return m, math.sqrt(sum((x - m) ** 2 for x in v) / len(v))

def cmd_nonblank(path):  # mean code value and spread: a rendered Cornell box, not a flat frame
    m, s = stats(png(path))
    print('mean %.2f sd %.2f' % (m, s))
    return 0 if m > 10 and s > 5 else 1

def cmd_same(a, b, tol):  # same film, tone-mapped on the GPU (float) and the CPU (double)
    A, B = png(a), png(b)
    if A[:2] != B[:2]: print('sizes differ', A[:2], B[:2]); return 1
    diffs = [abs(x - y) for ra, rb in zip(A[2], B[2]) for pa, pb in zip(ra, rb) for x, y in zip(pa, pb)]
    n = sum(1 for d in diffs if d)
    print('max |diff| %d codes, %d of %d values differ' % (max(diffs), n, len(diffs)))
    return 0 if max(diffs) <= int(tol) and n <= len(diffs) // 100 else 1

def cmd_stat(a, b):
    # Two independent renders (different seeds) of the same view at the same spp: each pixel's
    # tone-mapped value has the same distribution in both, so the per-pixel differences (summed
    # over RGB, independent across pixels, bounded by the 8-bit clamp) have mean 0. z-test on the
    # whole image (|z| < 4) and on each of 4x4 blocks (|z| < 4.5, Bonferroni for 16 blocks).
    A, B = png(a), png(b)
    if A[:2] != B[:2]: print('sizes differ', A[:2], B[:2]); return 1
    w, h = A[:2]
    def z(ds):
        n = len(ds); m = sum(ds) / n; var = sum((d - m) ** 2 for d in ds) / (n - 1)
        return m / math.sqrt(var / n) if var > 0 else (0.0 if m == 0 else float('inf'))
    d = [[sum(A[2][y][x]) - sum(B[2][y][x]) for x in range(w)] for y in range(h)]
    zs = z([v for row in d for v in row])
    worst = 0.0
    for by in range(4):
        for bx in range(4):
            blk = [d[y][x] for y in range(by * h // 4, (by + 1) * h // 4) for x in range(bx * w // 4, (bx + 1) * w // 4)]
            worst = max(worst, abs(z(blk)))
    print('image z %.2f, worst block |z| %.2f' % (zs, worst))
    return 0 if abs(zs) < 4 and worst < 4.5 else 1

def cmd_onscreen(screenpath, shot):  # the window (at 0,0, no window manager) shows the screenshot
    S = png(shot)
    W = xwd(screenpath, 0, 0, S[0], S[1])
    diffs = [abs(x - y) for ra, rb in zip(S[2], W[2]) for pa, pb in zip(ra, rb) for x, y in zip(pa, pb)]
    print('on screen vs screenshot: max |diff| %d' % max(diffs))
    return 0 if max(diffs) == 0 else 1

def cmd_screenmean(screenpath, w, h):
    print('%.2f' % stats(xwd(screenpath, 0, 0, int(w), int(h)))[0]); return 0

sys.exit(globals()['cmd_' + sys.argv[1]](*sys.argv[2:]))
EOF
img() { python3 "$work/img.py" "$@"; }

W=64 H=48 N=16

# ---- 1. Same view, seed and spp as a headless render: the same film, the same pixels ------------
"$nusselt" preview --width $W --height $H --frames $N --screenshot "$work/shot.png" --exr "$work/preview.exr" \
  2>"$work/preview.err"
status=$?
[ $status -eq 0 ] || fail "preview exit $status: $(cat "$work/preview.err")"
grep -q "validation" "$work/preview.err" && fail "validation messages: $(grep validation "$work/preview.err" | head -3)"
"$nusselt" render --width $W --height $H --spp $N -o "$work/render.exr" --png "$work/render.png" -q || fail "render exit $?"
spp=$("$nusselt" info "$work/preview.exr" | sed -n 's/^  nusselt\/spp: //p')
[ "$spp" = $N ] || fail "preview EXR spp '$spp' (want $N)"
out=$(img nonblank "$work/shot.png") && ok "screenshot not blank: $out" || fail "screenshot blank: $out"
diff_out=$("$nusselt" diff "$work/preview.exr" "$work/render.exr")
echo "$diff_out" | grep -q "max |diff| 0$" && ok "preview film = headless film (same seed, $N spp)" ||
  fail "preview film differs from the headless one: $diff_out"
out=$(img same "$work/shot.png" "$work/render.png" 1) && ok "screenshot = render --png: $out" ||
  fail "screenshot vs render --png: $out"

# ---- 2. Independent seeds: the screenshot agrees statistically with the headless PNG ------------
"$nusselt" preview --width $W --height $H --frames $N --seed 101 --screenshot "$work/shot101.png" -q ||
  fail "preview --seed 101 exit $?"
"$nusselt" render --width $W --height $H --spp $N --seed 202 -o "$work/render202.exr" --png "$work/render202.png" -q ||
  fail "render --seed 202 exit $?"
out=$(img stat "$work/shot101.png" "$work/render202.png") && ok "statistical agreement: $out" ||
  fail "screenshot (seed 101) vs render (seed 202) disagree: $out"
# The check has teeth: one stop of exposure is detected.
"$nusselt" preview --width $W --height $H --frames $N --seed 101 --exposure 1 --screenshot "$work/bright.png" -q
out=$(img stat "$work/bright.png" "$work/render202.png") && fail "a one-stop exposure error went unnoticed: $out" ||
  ok "a one-stop exposure error is detected: $out"

# ---- 3. Resizes during the run: swapchain and film follow the window, no validation message ------
"$nusselt" preview --width $W --height $H --frames 30 --test-resize 120x90 --test-resize 40x72 \
  --screenshot "$work/resized.png" --exr "$work/resized.exr" 2>"$work/resize.err"
status=$?
[ $status -eq 0 ] || fail "resizing preview exit $status: $(tail -5 "$work/resize.err")"
grep -q "validation" "$work/resize.err" && fail "validation messages while resizing: $(grep validation "$work/resize.err" | head -3)"
"$nusselt" info "$work/resized.exr" | head -1 | grep -q "40x72" && ok "resized twice: film follows the window (40x72)" ||
  fail "film after resizing: $("$nusselt" info "$work/resized.exr" | head -1)"
img nonblank "$work/resized.png" >/dev/null || fail "screenshot after resizing is blank"

# ---- 4. What is on the screen is the screenshot; an idle window sleeps ---------------------------
"$nusselt" preview --width $W --height $H --max-spp 4 --screenshot "$work/live.png" -q 2>"$work/live.err" &
pid=$!
shown=
for _ in $(seq 120); do
  sleep 0.5
  m=$(img screenmean "$screen" $W $H 2>/dev/null) || continue
  if awk "BEGIN{exit !($m > 10)}"; then shown=$m; break; fi
done
if [ -z "$shown" ]; then
  fail "nothing appeared on the screen: $(cat "$work/live.err")"
  kill -TERM $pid 2>/dev/null
  wait $pid
else
  sleep 2  # reaches 4 spp and goes idle
  t0=$(awk '{print $14 + $15}' /proc/$pid/stat)
  sleep 3
  t1=$(awk '{print $14 + $15}' /proc/$pid/stat)
  ticks=$((t1 - t0))
  hz=$(getconf CLK_TCK)
  # 3 s idle: less than 5% of one core.
  [ $ticks -lt $((hz * 3 / 20)) ] && ok "idle window: $ticks CPU ticks in 3 s" || fail "idle window spins: $ticks ticks in 3 s"
  cp "$screen" "$work/screen.xwd"  # the window while it is still open
  kill -TERM $pid
  wait $pid
  status=$?
  [ $status -eq 130 ] || fail "SIGTERM: exit status $status (want 130): $(cat "$work/live.err")"
  grep -q "validation" "$work/live.err" && fail "validation messages: $(grep validation "$work/live.err" | head -3)"
  out=$(img onscreen "$work/screen.xwd" "$work/live.png") && ok "$out" || fail "$out"
fi

# ---- 5. Keys (typed by the harness, one per frame) under validation -----------------------------
"$nusselt" render --width $W --height $H --spp 4 -o "$work/render4.exr" -q || fail "render --spp 4 exit $?"
# A camera move restarts accumulation on a new view; R restores the scene's camera exactly.
"$nusselt" preview --width $W --height $H --frames 100 --max-spp 4 --test-keys Left --exr "$work/moved.exr" -q ||
  fail "preview with Left exit $?"
"$nusselt" diff "$work/moved.exr" "$work/render4.exr" | grep -q "max |diff| 0$" && fail "Left did not move the camera"
"$nusselt" preview --width $W --height $H --frames 100 --max-spp 4 --test-keys Left,Shift+Up,PageUp,R --exr "$work/reset.exr" -q ||
  fail "preview with R exit $?"
[ "$("$nusselt" info "$work/reset.exr" | sed -n 's/^  nusselt\/spp: //p')" = 4 ] || fail "spp after reset"
"$nusselt" diff "$work/reset.exr" "$work/render4.exr" | grep -q "max |diff| 0$" &&
  ok "camera keys move the view and R restores it (4 spp after the reset = headless 4 spp)" ||
  fail "after R: $("$nusselt" diff "$work/reset.exr" "$work/render4.exr")"
# S saves EXR + PNG in the current directory; L switches the estimator (a new Renderer); key 3
# switches to the analytic sampler (a new Renderer); exposure and
# tone map keys.
mkdir -p "$work/cwd"
(cd "$work/cwd" && "$nusselt" preview --width $W --height $H --frames 12 --test-keys S,L,3,Tab,],T,S \
  --exr "$work/keys.exr" >"$work/keys.out" 2>&1)
status=$?
[ $status -eq 0 ] || fail "preview with keys exit $status: $(tail -5 "$work/keys.out")"
grep -q "validation" "$work/keys.out" && fail "validation messages with keys: $(grep validation "$work/keys.out" | head -3)"
for f in preview-1.exr preview-1.png preview-2.exr preview-2.png; do [ -s "$work/cwd/$f" ] || fail "S did not write $f"; done
grep -q "lighting: nee" "$work/keys.out" || fail "L did not switch to nee"
"$nusselt" info "$work/cwd/preview-2.exr" | grep -q "nusselt/lighting: nee" || fail "saved EXR after L: lighting attribute"
grep -q "sampler: analytic" "$work/keys.out" || fail "key 3 did not switch to the analytic sampler"
"$nusselt" info "$work/keys.exr" | grep -q "nusselt/exposure: 0.5" || fail "] did not raise the exposure by half a stop"
[ $fails -eq 0 ] && ok "keys: save, lighting, sampler, exposure, tone map"

# ---- Saves are renders: `render --resume` continues a preview save bit for bit, and a moved
# view resumes at the view that was saved (its camera is in the record) --------------------------
"$nusselt" preview --width $W --height $H --frames 100 --max-spp 4 --exr "$work/psave.exr" -q || fail "preview save exit $?"
"$nusselt" render --width $W --height $H --spp 8 --resume "$work/psave.exr" -q || fail "render --resume of a preview save"
"$nusselt" render --width $W --height $H --spp 8 -o "$work/render8.exr" -q || fail "render --spp 8 exit $?"
"$nusselt" diff "$work/psave.exr" "$work/render8.exr" | grep -q "max |diff| 0$" &&
  ok "preview save (4 spp) resumed to 8 spp = headless 8 spp, bit for bit" ||
  fail "resumed preview save: $("$nusselt" diff "$work/psave.exr" "$work/render8.exr")"
"$nusselt" preview --width $W --height $H --frames 100 --max-spp 4 --test-keys Left --exr "$work/pmoved.exr" -q ||
  fail "preview moved save exit $?"
"$nusselt" preview --width $W --height $H --frames 100 --max-spp 8 --test-keys Left --exr "$work/pmoved8.exr" -q ||
  fail "preview moved 8 spp exit $?"
"$nusselt" render --width $W --height $H --spp 8 --resume "$work/pmoved.exr" -q || fail "render --resume of a moved view"
"$nusselt" diff "$work/pmoved.exr" "$work/pmoved8.exr" | grep -q "max |diff| 0$" &&
  ok "a moved view resumes at its own camera (= 8 spp of the moved preview)" ||
  fail "moved view resumed: $("$nusselt" diff "$work/pmoved.exr" "$work/pmoved8.exr")"

# ---- Path guiding: a guided preview (training passes of 1 spp, 127 training spp) accumulates the
# film of the guided headless render with those settings, its save resumes bit for bit (the guide
# trained again, its hash checked), and G switches guiding on --------------------------------------
"$nusselt" preview --width $W --height $H --frames 100 --max-spp 8 --guiding on --exr "$work/pguided.exr" -q ||
  fail "guided preview exit $?"
gr=(--width $W --height $H --guiding on --guide-train 127 --samples-per-pass 1 -q)
"$nusselt" render "${gr[@]}" --spp 8 -o "$work/rguided8.exr" || fail "guided render --spp 8 exit $?"
"$nusselt" diff "$work/pguided.exr" "$work/rguided8.exr" | grep -q "max |diff| 0$" &&
  ok "guided preview (8 frames) = guided headless render of 8 spp in 1-spp passes, bit for bit" ||
  fail "guided preview vs render: $("$nusselt" diff "$work/pguided.exr" "$work/rguided8.exr")"
"$nusselt" render --width $W --height $H --guiding on --spp 12 --resume "$work/pguided.exr" 2>"$work/gres.err" ||
  fail "render --resume of a guided preview save: $(cat "$work/gres.err")"
"$nusselt" render "${gr[@]}" --spp 12 -o "$work/rguided12.exr" || fail "guided render --spp 12 exit $?"
! grep -q warning "$work/gres.err" && "$nusselt" diff "$work/pguided.exr" "$work/rguided12.exr" | grep -q "max |diff| 0$" &&
  ok "guided preview save resumed to 12 spp = guided headless 12 spp, bit for bit" ||
  fail "guided preview save resumed: $(cat "$work/gres.err") $("$nusselt" diff "$work/pguided.exr" "$work/rguided12.exr")"
"$nusselt" preview --width $W --height $H --frames 100 --max-spp 4 --test-keys G --exr "$work/pg.exr" >"$work/pg.out" 2>&1 ||
  fail "preview with G exit $?: $(tail -3 "$work/pg.out")"
grep -q "guiding: on" "$work/pg.out" && "$nusselt" info "$work/pg.exr" | grep -q "nusselt/guiding: on" &&
  ok "G switches guiding on (the saved film is a guided render's)" || fail "G: $(cat "$work/pg.out")"

[ $fails -eq 0 ] && echo "preview checks pass"
exit $((fails > 0))
