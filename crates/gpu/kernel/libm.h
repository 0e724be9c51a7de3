/*
 * The transcendental functions of the step, ported to C from the Rust
 * `libm` crate (0.2), itself a port of musl's and FreeBSD's msun code, so
 * that the C step gives the bits `animats_engine::math` gives. Each is
 * checked against the crate on more than a million arguments, bit for bit
 * (crates/gpu/tests/libm.rs).
 *
 * ====================================================
 * Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
 *
 * Developed at SunPro, a Sun Microsystems, Inc. business.
 * Permission to use, copy, modify, and distribute this
 * software is freely granted, provided that this notice
 * is preserved.
 * ====================================================
 */
#ifndef ANIMATS_LIBM_H
#define ANIMATS_LIBM_H

#if defined(__CUDACC__) || defined(__CUDACC_RTC__)
#define AN_FN __device__ static inline
#else
#define AN_FN static inline
#endif

AN_FN unsigned long long an_bits(double x) {
    union { double d; unsigned long long u; } v;
    v.d = x;
    return v.u;
}

AN_FN double an_from_bits(unsigned long long u) {
    union { double d; unsigned long long u; } v;
    v.u = u;
    return v.d;
}

AN_FN double an_fabs(double x) { return an_from_bits(an_bits(x) & 0x7fffffffffffffffULL); }

/* atan(x): s_atan.c. */
AN_FN double an_atan(double x) {
    const double atanhi[4] = {
        4.63647609000806093515e-01, 7.85398163397448278999e-01,
        9.82793723247329054082e-01, 1.57079632679489655800e+00,
    };
    const double atanlo[4] = {
        2.26987774529616870924e-17, 3.06161699786838301793e-17,
        1.39033110312309984516e-17, 6.12323399573676603587e-17,
    };
    const double at[11] = {
        3.33333333333329318027e-01, -1.99999999998764832476e-01,
        1.42857142725034663711e-01, -1.11111104054623557880e-01,
        9.09088713343650656196e-02, -7.69187620504482999495e-02,
        6.66107313738753120669e-02, -5.83357013379057348645e-02,
        4.97687799461593236017e-02, -3.65315727442169155270e-02,
        1.62858201153657823623e-02,
    };
    unsigned int ix = (unsigned int)(an_bits(x) >> 32);
    unsigned int sign = ix >> 31;
    int id;
    ix &= 0x7fffffff;
    if (ix >= 0x44100000) {
        if (x != x) {
            return x;
        }
        double z = atanhi[3] + an_from_bits(0x0380000000000000ULL);
        return sign ? -z : z;
    }
    if (ix < 0x3fdc0000) {
        if (ix < 0x3e400000) {
            return x;
        }
        id = -1;
    } else {
        x = an_fabs(x);
        if (ix < 0x3ff30000) {
            if (ix < 0x3fe60000) {
                x = (2. * x - 1.) / (2. + x);
                id = 0;
            } else {
                x = (x - 1.) / (x + 1.);
                id = 1;
            }
        } else if (ix < 0x40038000) {
            x = (x - 1.5) / (1. + 1.5 * x);
            id = 2;
        } else {
            x = -1. / x;
            id = 3;
        }
    }
    double z = x * x;
    double w = z * z;
    double s1 = z * (at[0] + w * (at[2] + w * (at[4] + w * (at[6] + w * (at[8] + w * at[10])))));
    double s2 = w * (at[1] + w * (at[3] + w * (at[5] + w * (at[7] + w * at[9]))));
    if (id < 0) {
        return x - x * (s1 + s2);
    }
    z = atanhi[id] - ((x * (s1 + s2) - atanlo[id]) - x);
    return sign ? -z : z;
}

/* atan2(y, x): e_atan2.c. */
AN_FN double an_atan2(double y, double x) {
    const double pi = 3.1415926535897931160E+00;
    const double pi_lo = 1.2246467991473531772E-16;
    if (x != x || y != y) {
        return x + y;
    }
    unsigned long long bx = an_bits(x), by = an_bits(y);
    unsigned int ix = (unsigned int)(bx >> 32), lx = (unsigned int)bx;
    unsigned int iy = (unsigned int)(by >> 32), ly = (unsigned int)by;
    if (((ix - 0x3ff00000u) | lx) == 0) {
        return an_atan(y);
    }
    unsigned int m = ((iy >> 31) & 1) | ((ix >> 30) & 2);
    ix &= 0x7fffffff;
    iy &= 0x7fffffff;
    if ((iy | ly) == 0) {
        switch (m) {
        case 0:
        case 1: return y;
        case 2: return pi;
        default: return -pi;
        }
    }
    if ((ix | lx) == 0) {
        return (m & 1) ? -pi / 2.0 : pi / 2.0;
    }
    if (ix == 0x7ff00000) {
        if (iy == 0x7ff00000) {
            switch (m) {
            case 0: return pi / 4.0;
            case 1: return -pi / 4.0;
            case 2: return 3.0 * pi / 4.0;
            default: return -3.0 * pi / 4.0;
            }
        } else {
            switch (m) {
            case 0: return 0.0;
            case 1: return -0.0;
            case 2: return pi;
            default: return -pi;
            }
        }
    }
    if (ix + (64u << 20) < iy || iy == 0x7ff00000) {
        return (m & 1) ? -pi / 2.0 : pi / 2.0;
    }
    double z;
    if ((m & 2) && iy + (64u << 20) < ix) {
        z = 0.0;
    } else {
        z = an_atan(an_fabs(y / x));
    }
    switch (m) {
    case 0: return z;
    case 1: return -z;
    case 2: return pi - (z - pi_lo);
    default: return (z - pi_lo) - pi;
    }
}

/* hypot(x, y): e_hypot.c as the libm crate has it, its operations in
 * its order: |x| >= |y| arranged, the special cases, then the sum of the
 * squares split exactly (sq) for a correctly rounded square root. */
AN_FN void an_hypot_sq(double x, double *hi, double *lo) {
    double xc = x * 134217729.0; /* 2^27 + 1 */
    double xh = x - xc + xc;
    double xl = x - xh;
    *hi = x * x;
    *lo = xh * xh - *hi + 2.0 * xh * xl + xl * xl;
}
AN_FN double an_hypot(double x, double y) {
    unsigned long long ux = an_bits(x) & 0x7fffffffffffffffULL, uy = an_bits(y) & 0x7fffffffffffffffULL;
    if (ux < uy) {
        unsigned long long t = ux;
        ux = uy;
        uy = t;
    }
    long long ex = (long long)(ux >> 52), ey = (long long)(uy >> 52);
    x = an_from_bits(ux);
    y = an_from_bits(uy);
    if (ey == 0x7ff) {
        return y;
    }
    if (ex == 0x7ff || uy == 0) {
        return x;
    }
    if (ex - ey > 64) {
        return x + y;
    }
    double z = 1.0;
    if (ex > 0x3ff + 510) {
        z = an_from_bits(0x6bb0000000000000ULL); /* 2^700 */
        x = x * an_from_bits(0x1430000000000000ULL);
        y = y * an_from_bits(0x1430000000000000ULL);
    } else if (ey < 0x3ff - 450) {
        z = an_from_bits(0x1430000000000000ULL); /* 2^-700 */
        x = x * an_from_bits(0x6bb0000000000000ULL);
        y = y * an_from_bits(0x6bb0000000000000ULL);
    }
    double hx, lx, hy, ly;
    an_hypot_sq(x, &hx, &lx);
    an_hypot_sq(y, &hy, &ly);
    return z * sqrt(ly + lx + hy + hx);
}

/* asin(x): e_asin.c as the libm crate has it (Raibert's foot placement). */
AN_FN double an_asin_r(double z) {
    double p = z * (1.66666666666666657415e-01 +
                    z * (-3.25565818622400915405e-01 +
                         z * (2.01212532134862925881e-01 +
                              z * (-4.00555345006794114027e-02 +
                                   z * (7.91534994289814532176e-04 + z * 3.47933107596021167570e-05)))));
    double q = 1.0 + z * (-2.40339491173441421878e+00 +
                          z * (2.02094576023350569471e+00 +
                               z * (-6.88283971605453293030e-01 + z * 7.70381505559019352791e-02)));
    return p / q;
}
AN_FN double an_asin(double x) {
    const double pio2_hi = 1.57079632679489655800e+00, pio2_lo = 6.12323399573676603587e-17;
    unsigned int hx = (unsigned int)(an_bits(x) >> 32);
    unsigned int ix = hx & 0x7fffffffu;
    if (ix >= 0x3ff00000u) { /* |x| >= 1 or NaN */
        unsigned int lx = (unsigned int)an_bits(x);
        if (((ix - 0x3ff00000u) | lx) == 0) {
            return x * pio2_hi + an_from_bits(0x3870000000000000ULL);
        }
        return 0.0 / (x - x);
    }
    if (ix < 0x3fe00000u) { /* |x| < 0.5 */
        if (ix >= 0x00100000u && ix < 0x3e500000u) {
            return x;
        }
        return x + x * an_asin_r(x * x);
    }
    double z = (1.0 - an_fabs(x)) * 0.5;
    double s = sqrt(z);
    double r = an_asin_r(z);
    if (ix >= 0x3fef3333u) { /* |x| > 0.975 */
        x = pio2_hi - (2.0 * (s + s * r) - pio2_lo);
    } else {
        double f = an_from_bits(an_bits(s) & 0xffffffff00000000ULL);
        double c = (z - f * f) / (s + f);
        x = 0.5 * pio2_hi - (2.0 * s * r - (pio2_lo - 2.0 * c) - (0.5 * pio2_hi - 2.0 * f));
    }
    return hx >> 31 ? -x : x;
}

#endif
