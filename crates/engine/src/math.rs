//! The transcendental functions of the step path, in one place.
//!
//! Every creature, force, sensor, brain and body builder calls these
//! instead of `std`'s methods: `f64::sin` and its kin call the platform's
//! C library, whose last bits differ between operating systems, so a run
//! would not give the same bits on every machine. Each is the `libm`
//! crate's, a Rust port of musl's (FreeBSD's msun) code: the same
//! arithmetic on every platform, and one list of functions for a GPU
//! kernel to port.
//!
//! (Why musl's `atan2`: one of our own, branch-free, from a table of
//! Taylor polynomials evaluated with fused multiply-adds, is more accurate
//! — largest error 0.990 against 1.385 ulp on 200,000 pairs — and made the
//! roobot's evaluation only 4–7 % faster, 1.601 against 1.715 ms
//! (`animats bench hopper --runs 15`, AMD EPYC, 2026-12-02): too little to
//! re-pin every figure that depends on the joints' bits. It is kept
//! applicable, ported to the GPU kernel's C, with its test, figures and
//! commands, in `bench/atan2/`. An earlier table-driven one, and musl's
//! operations four joints at a time with its branches turned into
//! selections, gave nothing measurable, 2026-11-27 and 2026-11-30.)

/// `sin x`.
#[inline]
pub fn sin(x: f64) -> f64 {
    libm::sin(x)
}

/// Lanes of [`sin_lanes`].
pub const LANES: usize = 4;

/// [`sin`] of [`LANES`] arguments at once, each lane the bits of
/// `sin(x[i])`.
///
/// musl's `sin` (the `libm` crate's port) with its branches turned into
/// selections, for arguments past `9π/4` and below `2²⁰ π/2` whose
/// reduction needs one round (musl's `rem_pio2` medium path; its
/// cancellation check holds): each lane reduces its argument, computes
/// both musl's `k_sin` and `k_cos` of the remainder and keeps the one its
/// quadrant asks for, in musl's operations and order, with no branch, so
/// the compiler computes the lanes side by side in vectors. Any other
/// argument (small, huge, not finite, or a reduction that cancels) sends
/// every lane to [`sin`]. (`tests/math.rs` holds every lane to
/// `libm::sin` on 10⁷ arguments and the edges of the range.)
#[inline]
pub fn sin_lanes(x: [f64; LANES]) -> [f64; LANES] {
    const TO_INT: f64 = 6_755_399_441_055_744.0; // 1.5·2⁵²
    const INV_PIO2: f64 = f64::from_bits(0x3FE45F30_6DC9C883);
    const PIO2_1: f64 = f64::from_bits(0x3FF921FB_54400000);
    const PIO2_1T: f64 = f64::from_bits(0x3DD0B461_1A626331);
    const S1: f64 = f64::from_bits(0xBFC55555_55555549);
    const S2: f64 = f64::from_bits(0x3F811111_1110F8A6);
    const S3: f64 = f64::from_bits(0xBF2A01A0_19C161D5);
    const S4: f64 = f64::from_bits(0x3EC71DE3_57B1FE7D);
    const S5: f64 = f64::from_bits(0xBE5AE5E6_8A2B9CEB);
    const S6: f64 = f64::from_bits(0x3DE5D93A_5ACFD57C);
    const C1: f64 = f64::from_bits(0x3FA55555_5555554C);
    const C2: f64 = f64::from_bits(0xBF56C16C_16C15177);
    const C3: f64 = f64::from_bits(0x3EFA01A0_19CB1590);
    const C4: f64 = f64::from_bits(0xBE927E4F_809C52AD);
    const C5: f64 = f64::from_bits(0x3E21EE9E_BDB4B1C4);
    const C6: f64 = f64::from_bits(0xBDA8FAE9_BE8838D4);
    let mut q = [0u64; LANES];
    let (mut y0, mut y1) = ([0.0; LANES], [0.0; LANES]);
    let mut general = true;
    for i in 0..LANES {
        let x = x[i];
        let ix = (x.to_bits() >> 32) as u32 & 0x7fff_ffff;
        // rem_pio2's medium path, its first round. `tmp` is 1.5·2⁵² + n
        // exactly (its unit in the last place is 1), so its last two bits
        // are musl's `n & 3`.
        let tmp = x * INV_PIO2 + TO_INT;
        q[i] = tmp.to_bits() & 3;
        let f_n = tmp - TO_INT;
        let r = x - f_n * PIO2_1;
        let w = f_n * PIO2_1T;
        y0[i] = r - w;
        let ey = (y0[i].to_bits() >> 52) as i32 & 0x7ff;
        let ex = (ix >> 20) as i32;
        general &= (ix > 0x401c_463b) & (ix < 0x4139_21fb) & (ex - ey <= 16);
        y1[i] = (r - y0[i]) - w;
    }
    if !general {
        return std::array::from_fn(|i| sin(x[i]));
    }
    let mut out = [0.0; LANES];
    for i in 0..LANES {
        let (x, y) = (y0[i], y1[i]);
        let z = x * x;
        let w = z * z;
        // k_sin(x, y, 1)
        let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
        let v = z * x;
        let s = x - ((z * (0.5 * y - v * r) - y) - v * S1);
        // k_cos(x, y)
        let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
        let hz = 0.5 * z;
        let w = 1.0 - hz;
        let c = w + (((1.0 - w) - hz) + (z * r - x * y));
        // Quadrant 0: k_sin; 1: k_cos; 2: −k_sin; 3: −k_cos, chosen by
        // masks (a negation flips the sign bit).
        let odd = 0u64.wrapping_sub(q[i] & 1);
        let pick = (s.to_bits() & !odd) | (c.to_bits() & odd);
        out[i] = f64::from_bits(pick ^ ((q[i] & 2) << 62));
    }
    out
}

/// [`exp`] of [`LANES`] arguments at once, each lane the bits of
/// `exp(x[i])`.
///
/// musl's `exp` (the `libm` crate's port) with its branches turned into
/// selections, for `2⁻²⁸ < |x| < 708.39` (below, musl returns `1 + x`;
/// above, it handles overflow): each lane picks musl's `k` (0 below
/// ½ ln 2, ±1 below 1.5 ln 2, else `⌊x/ln 2 ± ½⌉` truncated), reduces,
/// evaluates musl's polynomial and scales by `2ᵏ` (musl's `scalbn` is
/// one multiplication for these `k`), in musl's operations and order.
/// (`k = 0` goes through the same reduction: `x − 0·ln2hi` is `x`.) Any
/// other argument takes [`exp`] in its lane. (`tests/math.rs` holds
/// every lane to `libm::exp` on 10⁷ arguments and the edges.)
#[inline]
pub fn exp_lanes(x: [f64; LANES]) -> [f64; LANES] {
    const LN2HI: f64 = f64::from_bits(0x3FE62E42_FEE00000);
    const LN2LO: f64 = f64::from_bits(0x3DEA39EF_35793C76);
    const INVLN2: f64 = f64::from_bits(0x3FF71547_652B82FE);
    const P1: f64 = f64::from_bits(0x3FC55555_5555553E);
    const P2: f64 = f64::from_bits(0xBF66C16C_16BEBD93);
    const P3: f64 = f64::from_bits(0x3F11566A_AF25DE2C);
    const P4: f64 = f64::from_bits(0xBEBBBD41_C5D26BF1);
    const P5: f64 = f64::from_bits(0x3E663769_72BEA4D0);
    const BIAS: f64 = 6_755_399_441_056_767.0; // 1.5·2⁵² + 1023
    let mut general = [true; LANES];
    let mut out = [0.0; LANES];
    for i in 0..LANES {
        let x = x[i];
        let high = (x.to_bits() >> 32) as u32;
        let hx = high & 0x7fff_ffff;
        let negative = high >> 31 == 1;
        general[i] = (hx > 0x3e30_0000) & (hx < 0x4086_232b);
        let near = if negative { -1.0 } else { 1.0 };
        let far = (INVLN2 * x + if negative { -0.5 } else { 0.5 }).trunc();
        let k = if hx >= 0x3ff0_a2b2 {
            far
        } else if hx > 0x3fd6_2e42 {
            near
        } else {
            0.0
        };
        let hi = x - k * LN2HI;
        let lo = k * LN2LO;
        let x = hi - lo;
        let xx = x * x;
        let c = x - xx * (P1 + xx * (P2 + xx * (P3 + xx * (P4 + xx * P5))));
        let y = 1. + (x * c / (2. - c) - lo + hi);
        // 2^k: k + 1023 in the last bits of 1.5·2⁵² + 1023 + k.
        let scale = f64::from_bits(((k + BIAS).to_bits() & 0x7ff) << 52);
        out[i] = y * scale;
    }
    // A lane outside the range takes `exp` itself, the others keep
    // theirs (a network's zeros, near the start of a run, had sent whole
    // groups to `exp` one by one).
    if general != [true; LANES] {
        for i in 0..LANES {
            if !general[i] {
                out[i] = exp(x[i]);
            }
        }
    }
    out
}

/// `cos x`.
#[inline]
pub fn cos(x: f64) -> f64 {
    libm::cos(x)
}

/// `(sin x, cos x)`.
#[inline]
pub fn sincos(x: f64) -> (f64, f64) {
    libm::sincos(x)
}

/// `tan x`.
#[inline]
pub fn tan(x: f64) -> f64 {
    libm::tan(x)
}

/// The cube root.
#[inline]
pub fn cbrt(x: f64) -> f64 {
    libm::cbrt(x)
}

/// `√(x² + y²)` without overflow on the way.
#[inline]
pub fn hypot(x: f64, y: f64) -> f64 {
    libm::hypot(x, y)
}

/// `eˣ`.
#[inline]
pub fn exp(x: f64) -> f64 {
    libm::exp(x)
}

/// The natural logarithm.
#[inline]
pub fn log(x: f64) -> f64 {
    libm::log(x)
}

/// `xʸ`.
#[inline]
pub fn pow(x: f64, y: f64) -> f64 {
    libm::pow(x, y)
}

/// `tanh x`.
#[inline]
pub fn tanh(x: f64) -> f64 {
    libm::tanh(x)
}

/// `asin x`, in `[−π/2, π/2]`.
#[inline]
pub fn asin(x: f64) -> f64 {
    libm::asin(x)
}

/// IEEE remainder: `x − n y` with `n` the integer nearest `x / y`.
#[inline]
pub fn remainder(x: f64, y: f64) -> f64 {
    libm::remainder(x, y)
}

/// `atan x`, in `[−π/2, π/2]`.
#[inline]
pub fn atan(x: f64) -> f64 {
    libm::atan(x)
}

/// The angle of the point `(x, y)` from the x axis, in `[−π, π]`.
#[inline]
pub fn atan2(y: f64, x: f64) -> f64 {
    libm::atan2(y, x)
}
