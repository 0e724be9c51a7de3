"""Reads the `y x ours musl` lines (hex bits) of the atan2_pairs example
and prints, against mpmath's atan2 at 160 bits, the largest error of each
in units in the last place of the exact result, where it occurs, and how
many pairs the two round differently. Needs mpmath.

    python3 check.py pairs.txt
"""
import struct
import sys

import mpmath as mp

mp.mp.prec = 160


def f(h):
    return struct.unpack("<d", struct.pack("<Q", int(h, 16)))[0]


def ulp(v):
    v = abs(v)
    if v < 2.0**-1022:
        return mp.mpf(2) ** -1074
    return mp.mpf(2) ** (int(mp.floor(mp.log(v, 2))) - 52)


worst, where, count, differ = [0, 0], [None, None], 0, 0
for line in open(sys.argv[1]):
    y, x, ours, musl = map(f, line.split())
    if y != y or x != x:
        continue
    ref = mp.atan2(mp.mpf(y), mp.mpf(x))
    differ += ours != musl
    for i, v in enumerate((ours, musl)):
        if ref == 0:
            e = 0 if v == 0 else mp.inf
        else:
            e = abs(mp.mpf(v) - ref) / ulp(float(ref))
        if e > worst[i]:
            worst[i], where[i] = e, (y, x)
    count += 1
print(f"{count} pairs, {differ} rounded differently")
print(f"ours: largest error {float(worst[0]):.3f} ulp at (y, x) = {where[0]}")
print(f"musl: largest error {float(worst[1]):.3f} ulp at (y, x) = {where[1]}")
