//! The C port of the step's transcendental functions and hypot (kernel/libm.h,
//! kernel/trig.h)
//! against the engine's (`animats_engine::math`, the `libm` crate), bit for
//! bit, on more than a million arguments each: every special value, then
//! random ones spread over every binade and sign, then random bit patterns.

use animats_engine::math;
use animats_gpu::ported;

/// Random 64-bit patterns.
struct Bits(u64);

impl Bits {
    fn next(&mut self) -> u64 {
        // splitmix64
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// A double of random sign, mantissa and exponent in 2^lo … 2^hi.
    fn spread(&mut self, lo: i32, hi: i32) -> f64 {
        let b = self.next();
        let e = lo + (b % (hi - lo + 1) as u64) as i32;
        let m = 1.0 + (b >> 12) as f64 / (1u64 << 52) as f64;
        let v = m * 2f64.powi(e);
        if b & 1 == 0 {
            v
        } else {
            -v
        }
    }
}

const SPECIAL: [f64; 14] = [
    0.0,
    -0.0,
    1.0,
    -1.0,
    0.4375,
    1.1875,
    2.4375,
    f64::MIN_POSITIVE,
    5e-324,
    f64::MAX,
    -f64::MAX,
    f64::INFINITY,
    f64::NEG_INFINITY,
    f64::NAN,
];

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

#[test]
fn atan_is_the_libm_crate_s_to_the_bit() {
    let mut r = Bits(1);
    let mut args: Vec<f64> = SPECIAL.to_vec();
    args.extend((0..600_000).map(|_| r.spread(-40, 70)));
    args.extend((0..500_000).map(|_| f64::from_bits(r.next())));
    for x in args {
        let (c, rust) = (ported::atan(x), math::atan(x));
        assert!(same(c, rust), "atan({x:e}): C {c:e}, libm {rust:e}");
    }
}

#[test]
fn atan2_is_the_libm_crate_s_to_the_bit() {
    let mut r = Bits(2);
    for &y in &SPECIAL {
        for &x in &SPECIAL {
            let (c, rust) = (ported::atan2(y, x), math::atan2(y, x));
            assert!(same(c, rust), "atan2({y:e}, {x:e}): C {c:e}, libm {rust:e}");
        }
    }
    for i in 0..1_100_000 {
        let (y, x) = match i % 3 {
            // Near each other (the angle joints' case), far apart, anything.
            0 => (r.spread(-4, 4), r.spread(-4, 4)),
            1 => (r.spread(-80, 80), r.spread(-80, 80)),
            _ => (f64::from_bits(r.next()), f64::from_bits(r.next())),
        };
        let (c, rust) = (ported::atan2(y, x), math::atan2(y, x));
        assert!(same(c, rust), "atan2({y:e}, {x:e}): C {c:e}, libm {rust:e}");
    }
}

#[test]
fn asin_is_the_libm_crate_s_to_the_bit() {
    let mut r = Bits(6);
    let mut args: Vec<f64> = SPECIAL.to_vec();
    // Each branch's edges (2^-26, 0.5, 0.975, 1), Raibert's clamp (±0.9),
    // then [-1, 1] evenly, every binade below 1, and any bits.
    for edge in [2f64.powi(-26), 0.5, 0.975, 1.0, 0.9] {
        for k in -4i64..=4 {
            let x = f64::from_bits((edge.to_bits() as i64 + k) as u64);
            args.extend([x, -x]);
        }
    }
    args.extend((0..400_000).map(|_| 2.0 * (r.next() >> 11) as f64 / (1u64 << 53) as f64 - 1.0));
    args.extend((0..400_000).map(|_| r.spread(-1074, -1)));
    args.extend((0..300_000).map(|_| f64::from_bits(r.next())));
    for x in args {
        let (c, rust) = (ported::asin(x), math::asin(x));
        assert!(same(c, rust), "asin({x:e}): C {c:e}, libm {rust:e}");
    }
}

#[test]
fn hypot_is_the_libm_crate_s_to_the_bit() {
    let mut r = Bits(5);
    for &y in &SPECIAL {
        for &x in &SPECIAL {
            let (c, rust) = (ported::hypot(x, y), math::hypot(x, y));
            assert!(same(c, rust), "hypot({x:e}, {y:e}): C {c:e}, libm {rust:e}");
        }
    }
    for i in 0..1_100_000 {
        let (x, y) = match i % 4 {
            // Alike (a jellyfish's food sense), past the scaling's bounds
            // (2^510 and 2^-450), 64 binades apart or more, anything.
            0 => (r.spread(-8, 4), r.spread(-8, 4)),
            1 => (r.spread(400, 1023), r.spread(-1074, -400)),
            2 => (r.spread(-200, 200), r.spread(-200, 200)),
            _ => (f64::from_bits(r.next()), f64::from_bits(r.next())),
        };
        let (c, rust) = (ported::hypot(x, y), math::hypot(x, y));
        assert!(same(c, rust), "hypot({x:e}, {y:e}): C {c:e}, libm {rust:e}");
    }
}

#[test]
fn sin_and_cos_are_the_libm_crate_s_to_the_bit() {
    let mut r = Bits(3);
    let mut args: Vec<f64> = SPECIAL.to_vec();
    // Near multiples of π/2 (the reduction's hard cases), small and
    // medium arguments, huge ones (the long reduction), any bits.
    args.extend((1..20_000).flat_map(|k| {
        let x = k as f64 * std::f64::consts::FRAC_PI_2;
        [
            x,
            f64::from_bits(x.to_bits() + 1),
            f64::from_bits(x.to_bits() - 1),
            -x,
        ]
    }));
    args.extend((0..400_000).map(|_| r.spread(-30, 8)));
    args.extend((0..300_000).map(|_| r.spread(8, 40)));
    args.extend((0..100_000).map(|_| r.spread(40, 1023)));
    args.extend((0..250_000).map(|_| f64::from_bits(r.next())));
    assert!(args.len() > 1_000_000);
    for x in args {
        let (c, rust) = (ported::sin(x), math::sin(x));
        assert!(same(c, rust), "sin({x:e}): C {c:e}, libm {rust:e}");
        let (c, rust) = (ported::cos(x), math::cos(x));
        assert!(same(c, rust), "cos({x:e}): C {c:e}, libm {rust:e}");
    }
}

#[test]
fn exp_expm1_and_tanh_are_the_libm_crate_s_to_the_bit() {
    let mut r = Bits(4);
    let mut args: Vec<f64> = SPECIAL.to_vec();
    // Every branch: tiny, the primary range, near multiples of ln 2 (the
    // reduction's boundaries), up to overflow and underflow and past them,
    // the neural brains' usual range, any bits.
    args.extend((-1100..1100).flat_map(|k| {
        let x = k as f64 * std::f64::consts::LN_2;
        [
            x,
            f64::from_bits(x.to_bits() + 1),
            f64::from_bits(x.to_bits().wrapping_sub(1)),
        ]
    }));
    // The thresholds of overflow and underflow (as the crate writes them).
    #[allow(clippy::excessive_precision)]
    args.extend([
        709.782712893383973096,
        709.79,
        -708.39641853226410622,
        -745.13321910194110842,
        -745.2,
        20.0,
        22.0,
        0.5493,
        0.2554,
    ]);
    args.extend((0..300_000).map(|_| r.spread(-60, 0)));
    args.extend((0..300_000).map(|_| r.spread(0, 10)));
    args.extend((0..200_000).map(|_| (r.next() as f64 / u64::MAX as f64 - 0.5) * 1600.0));
    args.extend((0..200_000).map(|_| f64::from_bits(r.next())));
    assert!(args.len() > 1_000_000);
    for x in args {
        let (c, rust) = (ported::exp(x), math::exp(x));
        assert!(same(c, rust), "exp({x:e}): C {c:e}, libm {rust:e}");
        let (c, rust) = (ported::expm1(x), libm::expm1(x));
        assert!(same(c, rust), "expm1({x:e}): C {c:e}, libm {rust:e}");
        let (c, rust) = (ported::tanh(x), math::tanh(x));
        assert!(same(c, rust), "tanh({x:e}): C {c:e}, libm {rust:e}");
    }
}
