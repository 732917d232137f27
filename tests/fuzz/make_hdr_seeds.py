#!/usr/bin/env python3
"""Writes the seeds of tests/fuzz/corpus/hdr (fuzz_hdr): small Radiance RGBE files that between
them reach every branch of io/radiance_hdr.cpp's decoder: flat pixels, new-style run-length
scanlines (runs and literals), an old-style run and an EXPOSURE line. Standard library only."""
import os
import sys

# The RGBE encoding of the test maps (one definition in tools/).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tools"))
from make_env_maps import rgbe  # noqa: E402

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "hdr")


def head(w, h, extra=b""):
    return b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n" + extra + b"\n-Y %d +X %d\n" % (h, w)


def px(x, y):
    return rgbe([0.1 + x * 0.05, 0.5, 2.0 ** (y - 2)])


def rle_line(pixels):
    b = bytes([2, 2, len(pixels) >> 8, len(pixels) & 255])
    for c in range(4):
        vals = [p[c] for p in pixels]
        i = 0
        while i < len(vals):
            r = 1
            while i + r < len(vals) and r < 127 and vals[i + r] == vals[i]:
                r += 1
            if r >= 3:
                b += bytes([128 + r, vals[i]])
                i += r
            else:
                n = min(len(vals) - i, 128)
                b += bytes([n]) + bytes(vals[i:i + n])
                i += n
    return b


def main():
    os.makedirs(OUT, exist_ok=True)
    seeds = {
        "flat_4x2.hdr": head(4, 2) + b"".join(px(x, y) for y in range(2) for x in range(4)),
        "rle_16x2.hdr": head(16, 2) + b"".join(rle_line([px(x // 4, y) for x in range(16)]) for y in range(2)),
        "oldrun_exposure.hdr": head(6, 1, b"EXPOSURE=0.5\n") + px(1, 1) + bytes([1, 1, 1, 5]),
    }
    for name, data in seeds.items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)
        print("wrote", name)


if __name__ == "__main__":
    main()
