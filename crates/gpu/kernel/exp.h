/*
 * exp, expm1 and tanh ported to C from the Rust `libm` crate (0.2.16), a
 * port of FreeBSD's msun (e_exp.c, s_expm1.c) and musl's tanh.c, so that
 * the neural brains of the C step give the bits `animats_engine::math`
 * gives. Checked against the crate on more than a million arguments each,
 * bit for bit (crates/gpu/tests/libm.rs).
 *
 * ====================================================
 * Copyright (C) 2004 by Sun Microsystems, Inc. All rights reserved.
 *
 * Permission to use, copy, modify, and distribute this
 * software is freely granted, provided that this notice
 * is preserved.
 * ====================================================
 */
#ifndef ANIMATS_EXP_H
#define ANIMATS_EXP_H

#include "libm.h"
#if !defined(__CUDACC__) && !defined(__CUDACC_RTC__)
#include <math.h>
#endif

/* exp(x): e_exp.c. */
AN_FN double an_exp(double x) {
    const double ln2hi = 6.93147180369123816490e-01, ln2lo = 1.90821492927058770002e-10,
                 invln2 = 1.44269504088896338700e+00, p1 = 1.66666666666666019037e-01,
                 p2 = -2.77777777770155933842e-03, p3 = 6.61375632143793436117e-05,
                 p4 = -1.65339022054652515390e-06, p5 = 4.13813679705723846039e-08;
    double x1p1023 = an_from_bits(0x7fe0000000000000ULL);
    double hi, lo, c, xx, y;
    int k;
    unsigned int hx = (unsigned int)(an_bits(x) >> 32);
    int sign = (int)(hx >> 31);
    hx &= 0x7fffffff;
    if (hx >= 0x4086232b) { /* |x| >= 708.39... */
        if (x != x) {
            return x;
        }
        if (x > 709.782712893383973096) {
            x *= x1p1023;
            return x;
        }
        if (x < -708.39641853226410622) {
            if (x < -745.13321910194110842) {
                return 0.0;
            }
        }
    }
    if (hx > 0x3fd62e42) { /* |x| > 0.5 ln2 */
        if (hx >= 0x3ff0a2b2) { /* |x| >= 1.5 ln2 */
            k = (int)(invln2 * x + (sign ? -0.5 : 0.5));
        } else {
            k = 1 - sign - sign;
        }
        hi = x - (double)k * ln2hi;
        lo = (double)k * ln2lo;
        x = hi - lo;
    } else if (hx > 0x3e300000) { /* |x| > 2^-28 */
        k = 0;
        hi = x;
        lo = 0.0;
    } else {
        return 1.0 + x;
    }
    xx = x * x;
    c = x - xx * (p1 + xx * (p2 + xx * (p3 + xx * (p4 + xx * p5))));
    y = 1.0 + (x * c / (2.0 - c) - lo + hi);
    return k == 0 ? y : scalbn(y, k);
}

/* exp(x) - 1: s_expm1.c. */
AN_FN double an_expm1(double x) {
    const double o_threshold = 7.09782712893383973096e+02, ln2_hi = 6.93147180369123816490e-01,
                 ln2_lo = 1.90821492927058770002e-10, invln2 = 1.44269504088896338700e+00,
                 q1 = -3.33333333333331316428e-02, q2 = 1.58730158725481460165e-03,
                 q3 = -7.93650757867487942473e-05, q4 = 4.00821782732936239552e-06,
                 q5 = -2.01099218183624371326e-07;
    double hi, lo, c, t, y;
    int k;
    unsigned long long ui = an_bits(x);
    unsigned int hx = (unsigned int)((ui >> 32) & 0x7fffffff);
    int sign = (int)(ui >> 63);
    if (hx >= 0x4043687A) { /* |x| >= 56 ln2 */
        if (x != x) {
            return x;
        }
        if (sign) {
            return -1.0;
        }
        if (x > o_threshold) {
            x *= an_from_bits(0x7fe0000000000000ULL);
            return x;
        }
    }
    if (hx > 0x3fd62e42) { /* |x| > 0.5 ln2 */
        if (hx < 0x3FF0A2B2) { /* and |x| < 1.5 ln2 */
            if (!sign) {
                hi = x - ln2_hi;
                lo = ln2_lo;
                k = 1;
            } else {
                hi = x + ln2_hi;
                lo = -ln2_lo;
                k = -1;
            }
        } else {
            k = (int)(invln2 * x + (sign ? -0.5 : 0.5));
            t = (double)k;
            hi = x - t * ln2_hi;
            lo = t * ln2_lo;
        }
        x = hi - lo;
        c = (hi - x) - lo;
    } else if (hx < 0x3c900000) { /* |x| < 2^-54 */
        return x;
    } else {
        c = 0.0;
        k = 0;
    }
    double hfx = 0.5 * x;
    double hxs = x * hfx;
    double r1 = 1.0 + hxs * (q1 + hxs * (q2 + hxs * (q3 + hxs * (q4 + hxs * q5))));
    t = 3.0 - r1 * hfx;
    double e = hxs * ((r1 - t) / (6.0 - x * t));
    if (k == 0) {
        return x - (x * e - hxs);
    }
    e = x * (e - c) - c;
    e -= hxs;
    if (k == -1) {
        return 0.5 * (x - e) - 0.5;
    }
    if (k == 1) {
        if (x < -0.25) {
            return -2.0 * (e - (x + 0.5));
        }
        return 1.0 + 2.0 * (x - e);
    }
    double twopk = an_from_bits((unsigned long long)(0x3ff + k) << 52);
    if (k < 0 || k > 56) {
        y = x - e + 1.0;
        if (k == 1024) {
            y = y * 2.0 * an_from_bits(0x7fe0000000000000ULL);
        } else {
            y = y * twopk;
        }
        return y - 1.0;
    }
    double uf = an_from_bits((unsigned long long)(0x3ff - k) << 52);
    if (k < 20) {
        y = (x - e + (1.0 - uf)) * twopk;
    } else {
        y = (x - (e + uf) + 1.0) * twopk;
    }
    return y;
}

/* tanh(x): musl's tanh.c. */
AN_FN double an_tanh(double x) {
    unsigned long long ui = an_bits(x);
    int sign = (int)(ui >> 63);
    ui &= 0x7fffffffffffffffULL;
    x = an_from_bits(ui);
    unsigned int w = (unsigned int)(ui >> 32);
    double t;
    if (w > 0x3fe193ea) { /* |x| > log(3)/2 or NaN */
        if (w > 0x40340000) { /* |x| > 20 or NaN */
            t = 1.0 - 0.0 / x;
        } else {
            t = an_expm1(2.0 * x);
            t = 1.0 - 2.0 / (t + 2.0);
        }
    } else if (w > 0x3fd058ae) { /* |x| > log(5/3)/2 */
        t = an_expm1(2.0 * x);
        t = t / (t + 2.0);
    } else if (w >= 0x00100000) { /* |x| >= 2^-1022 */
        t = an_expm1(-2.0 * x);
        t = -t / (t + 2.0);
    } else { /* subnormal */
        t = x;
    }
    return sign ? -t : t;
}

#endif
