"""Prints the tables of the atan2 in own_atan2.patch: for t = k/16 + u,
k = 0..16, the Taylor coefficients a1..a12 of atan(k/16 + u) (ATAN_COEF),
and atan(k/16), pi/2 - atan(k/16), pi - atan(k/16), pi/2 + atan(k/16),
each as the nearest double and the nearest double to what is left
(ATAN_BASE). Needs mpmath. `python3 gen.py c` prints them for C
(kernel/libm.h), as bit patterns; `python3 gen.py ref N` N pairs with
their atan2 to 256 bits (the engine's test data); `python3 gen.py bound`
the largest relative error of the truncation after degree 11, 12, 13."""
import math
import struct
import sys

import mpmath as mp

mp.mp.prec = 256
K, N = 16, 12


def hexf(x):
    return "0x%016X" % struct.unpack("<Q", struct.pack("<d", x))[0]


if len(sys.argv) > 1 and sys.argv[1] == "bound":
    # The first two omitted terms at |u| = h, relative to the row's smallest
    # result (row 0: atan u ~ u, so relative to u itself).
    h = mp.mpf(1) / (2 * K)
    for n in (11, 12, 13):
        worst = mp.mpf(0)
        for k in range(K + 1):
            c = mp.mpf(k) / K
            co = mp.taylor(mp.atan, c, n + 3)
            tail = sum(abs(co[j]) * h**j for j in range(n + 1, n + 3))
            worst = max(worst, tail / (h if k == 0 else mp.atan(c - h)))
        print("degree", n, "largest relative truncation error 2^%.1f" % float(mp.log(worst, 2)))
    sys.exit(0)

if len(sys.argv) > 1 and sys.argv[1] == "ref":
    # Pairs with atan2 to 256 bits, as the nearest double and the nearest
    # double to what is left: every direction at radius 1; radii 2^-1000 ..
    # 2^1000; near the axes, the diagonals and the table's breakpoints;
    # random bit patterns. For crates/engine/tests/data/atan2_reference.txt.
    import random

    rng = random.Random(20261202)
    pairs = []
    for i in range(int(sys.argv[2]) if len(sys.argv) > 2 else 3000):
        kind = i % 6
        if kind == 0:
            a = rng.uniform(-math.pi, math.pi)
            y, x = math.sin(a), math.cos(a)
        elif kind == 1:
            a = rng.uniform(-math.pi, math.pi)
            r = 2.0 ** rng.randint(-1000, 1000)
            y, x = r * math.sin(a), r * math.cos(a)
        elif kind == 2:
            # t = min/max near k/16 and its midpoints
            t = rng.randint(0, 32) / 32 * (1 + rng.uniform(-1e-12, 1e-12))
            t = min(t, 1.0)
            d = rng.uniform(0.5, 2.0)
            y, x = t * d, d
            if rng.random() < 0.5:
                y, x = x, y
            y, x = y * rng.choice((1, -1)), x * rng.choice((1, -1))
        elif kind == 3:
            # tiny angles and near the axes
            e = 2.0 ** rng.randint(-1070, -1)
            y, x = e * rng.uniform(0.5, 1), rng.uniform(0.5, 2)
            if rng.random() < 0.5:
                y, x = x, y
            y, x = y * rng.choice((1, -1)), x * rng.choice((1, -1))
        else:
            def bits():
                b = rng.getrandbits(64)
                return struct.unpack("<d", struct.pack("<Q", b))[0]

            y, x = bits(), bits()
            if not (math.isfinite(y) and math.isfinite(x)):
                continue
        if y == 0 or x == 0:
            continue  # mpmath's zeros have no sign: the special cases' test
        ref = mp.atan2(mp.mpf(y), mp.mpf(x))
        hi = float(ref)
        lo = float(ref - hi)
        pairs.append((y, x, hi, lo))
    for p in pairs:
        print(" ".join(hexf(v)[2:].lower() for v in p))
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
if len(sys.argv) > 1 and sys.argv[1] == "c":
    for name, rows, width in (("an_atan_coef", coef, N), ("an_atan_base", base, 8)):
        print("#if defined(__CUDACC__) || defined(__CUDACC_RTC__)\n__device__\n#endif")
        print("static const unsigned long long %s[%d][%d] = {" % (name, K + 1, width))
        for r in rows:
            print("    {" + ", ".join("%sULL" % hexf(x) for x in r) + "},")
        print("};")
    sys.exit(0)
print("const ATAN_COEF: [[f64; %d]; %d] = [" % (N, K + 1))
for r in coef:
    print("    [" + ", ".join("f(%s)" % hexf(x) for x in r) + "],")
print("];")
print("const ATAN_BASE: [[f64; 8]; %d] = [" % (K + 1))
for r in base:
    print("    [" + ", ".join("f(%s)" % hexf(x) for x in r) + "],")
print("];")
