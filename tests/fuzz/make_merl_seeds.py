#!/usr/bin/env python3
"""Writes the seeds of tests/fuzz/corpus/merl (fuzz_merl): small files in the MERL binary layout
(three little-endian int32 dimensions, then the red, green and blue tables of doubles) that between
them reach every branch of src/brdf/merl.cpp's decodeMerl: a whole 4 x 3 x 6 table, one with
"not measured" (negative) entries to fill, one with none measured, a NaN, an infinity, a value
too large, a truncated table, trailing bytes, the full-phi header (90, 90, 360) and a short
header. Standard library only."""
import math
import os
import struct

OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus", "merl")
DIMS = (4, 3, 6)


def table(dims, value):
    """Header and 3 channels of doubles; value(c, i, j, k) gives each entry."""
    h, d, p = dims
    vals = [value(c, i, j, k) for c in range(3) for i in range(h) for j in range(d) for k in range(p)]
    return struct.pack("<3i", *dims) + struct.pack("<%dd" % len(vals), *vals)


def smooth(c, i, j, k):
    return 100.0 * (c + 1) + 10.0 * i - 3.0 * j + math.cos(k)


def below_horizon(c, i, j, k):
    return -1.0 if j == 2 and k % 2 == 0 else smooth(c, i, j, k)


def with_entry(c0, i0, j0, k0, v):
    return lambda c, i, j, k: v if (c, i, j, k) == (c0, i0, j0, k0) else smooth(c, i, j, k)


def main():
    os.makedirs(OUT, exist_ok=True)
    good = table(DIMS, smooth)
    seeds = {
        "good_4x3x6.binary": good,
        "unmeasured_4x3x6.binary": table(DIMS, below_horizon),
        "none_measured_2x2x2.binary": table((2, 2, 2), lambda c, i, j, k: -1.0),
        "line_1x1x5.binary": table((1, 1, 5), lambda c, i, j, k: -1.0 if k != 3 else 1.0),
        "nan.binary": table(DIMS, with_entry(1, 2, 1, 4, float("nan"))),
        "inf.binary": table(DIMS, with_entry(2, 0, 0, 1, float("-inf"))),
        "too_large.binary": table(DIMS, with_entry(0, 3, 2, 5, 1e300)),
        "truncated.binary": good[:-8],
        "trailing.binary": good + b"\0",
        "full_phi_header.binary": struct.pack("<3i", 90, 90, 360) + good[12:],
        "short_header.binary": struct.pack("<2i", 90, 90),
    }
    for name, data in seeds.items():
        with open(os.path.join(OUT, name), "wb") as f:
            f.write(data)
        print("wrote", name, len(data), "bytes")


if __name__ == "__main__":
    main()
