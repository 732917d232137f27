#!/usr/bin/env python3
"""Writes the environment maps the benchmark and manual checks use, as Radiance RGBE (.hdr),
generated here (no binary blobs in the repository). Standard library only.

  sun.hdr        a sky: blue zenith to white horizon, dark ground, and a sun of 2 x 2 texels
                 whose radiance (mean of R, G, B) is SUN_RATIO (10^4) times the mean texel of the
                 map without the sun (4 texels at 10^4 x the mean of a map that includes them
                 cannot exist on 256 x 128: they alone would exceed it), at
                 elevation 40 degrees, azimuth 30 degrees to the right of -Z (map convention of
                 docs/environment.md). 256 x 128.
  directions.hdr each texel's colour encodes its centre direction d: 0.5 + 0.5 d (checks the
                 convention by eye: +X red, +Y green, +Z blue). 128 x 64.

usage: python3 tools/make_env_maps.py OUTDIR
"""
import math
import os
import struct
import sys

SUN_RATIO = 1.0e4


def rgbe(c):
    m = max(c)
    if m < 1e-32:
        return bytes(4)
    mant, e = math.frexp(m)
    f = mant * 256.0 / m
    return bytes([min(255, int(c[0] * f)), min(255, int(c[1] * f)), min(255, int(c[2] * f)), e + 128])


def write_hdr(path, w, h, pixels):
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
        for p in pixels:
            f.write(rgbe(p))
    print("wrote", path)


def direction(u, v):
    """The map convention: u = 0.5 + atan2(x, -z) / 2pi, v = acos(y) / pi."""
    theta, phi = v * math.pi, (u - 0.5) * 2 * math.pi
    return (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))


def sun_map(path, w=256, h=128):
    pix = []
    for y in range(h):
        for x in range(w):
            d = direction((x + 0.5) / w, (y + 0.5) / h)
            if d[1] > 0:
                t = d[1] ** 0.5
                pix.append([0.8 * (1 - t) + 0.25 * t, 0.85 * (1 - t) + 0.45 * t, 0.9 * (1 - t) + 1.0 * t])
            else:
                pix.append([0.12, 0.1, 0.08])
    mean = sum(sum(p) / 3 for p in pix) / len(pix)
    # the sun: 2 x 2 texels around elevation 40, azimuth +30 degrees (u = 0.5 + 30/360)
    su, sv = 0.5 + 30.0 / 360.0, (90.0 - 40.0) / 180.0
    sx, sy = int(su * w), int(sv * h)
    tint = (1.0, 0.95, 0.85)
    for yy in (sy - 1, sy):
        for xx in (sx - 1, sx):
            pix[yy * w + xx] = [SUN_RATIO * mean * c * 3 / sum(tint) for c in tint]
    final = sum(sum(p) / 3 for p in pix) / len(pix)
    print("sun texels: %.4g x the mean without the sun, %.4g x the mean with it" % (SUN_RATIO, SUN_RATIO * mean / final))
    write_hdr(path, w, h, pix)


def directions_map(path, w=128, h=64):
    pix = []
    for y in range(h):
        for x in range(w):
            d = direction((x + 0.5) / w, (y + 0.5) / h)
            pix.append([0.5 + 0.5 * d[0], 0.5 + 0.5 * d[1], 0.5 + 0.5 * d[2]])
    write_hdr(path, w, h, pix)


if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(out, exist_ok=True)
    sun_map(os.path.join(out, "sun.hdr"))
    directions_map(os.path.join(out, "directions.hdr"))
