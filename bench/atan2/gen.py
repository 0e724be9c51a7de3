"""Prints the tables of the atan2 in own_atan2.patch: for t = k/16 + u,
k = 0..16, the Taylor coefficients a1..a12 of atan(k/16 + u) (ATAN_COEF),
and atan(k/16), pi/2 - atan(k/16), pi - atan(k/16), pi/2 + atan(k/16),
each as the nearest double and the nearest double to what is left
(ATAN_BASE). Needs mpmath. `python3 gen.py bound` prints instead the
largest relative error of the truncation after degree 11, 12, 13."""
import struct
import sys

import mpmath as mp

mp.mp.prec = 256
K, N = 16, 12


def hexf(x):
    return "0x%016X" % struct.unpack("<Q", struct.pack("<d", x))[0]


if len(sys.argv) > 1 and sys.argv[1] == "bound":
    h = mp.mpf(1) / (2 * K)
    for n in (11, 12, 13):
        worst = mp.mpf(0)
        for k in range(K + 1):
            c = mp.mpf(k) / K
            co = mp.taylor(mp.atan, c, n + 3)
            tail = sum(abs(co[j]) * h**j for j in range(n + 1, n + 3))
            # Relative to the smallest result of the row (k = 0: atan u ~ u).
            low = h if k == 0 else mp.atan(c - h)
            if k == 0:
                tail = sum(abs(co[j]) * h ** (j - 1) for j in range(n + 1, n + 3))
                low = 1
            worst = max(worst, tail / low)
        print("degree", n, "largest relative truncation error 2^%.1f" % float(mp.log(worst, 2)))
    sys.exit(0)

coef, base = [], []
for k in range(K + 1):
    c = mp.mpf(k) / K
    co = mp.taylor(mp.atan, c, N)
    coef.append([float(co[n]) for n in range(1, N + 1)])
    a = mp.atan(c)
    row = []
    for v in (a, mp.pi / 2 - a, mp.pi - a, mp.pi / 2 + a):
        hi = float(v)
        row += [hi, float(v - hi)]
    base.append(row)
print("const ATAN_COEF: [[f64; %d]; %d] = [" % (N, K + 1))
for r in coef:
    print("    [" + ", ".join("f(%s)" % hexf(x) for x in r) + "],")
print("];")
print("const ATAN_BASE: [[f64; 8]; %d] = [" % (K + 1))
for r in base:
    print("    [" + ", ".join("f(%s)" % hexf(x) for x in r) + "],")
print("];")
