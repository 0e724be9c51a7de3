//! `math::sin_lanes` and `math::exp_lanes` against `math::sin` and
//! `math::exp` (the `libm` crate's musl port), bit for bit, lane by lane:
//! the edges of musl's ranges, its thresholds and their neighbours, each in
//! every lane beside ordinary arguments; the multiples of π/2 where its
//! reduction cancels; 10⁷ random arguments, spread over every binade up to
//! 2²⁴ and over an oscillator's phases; random bit patterns.

use animats_engine::math::{exp, exp_lanes, sin, sin_lanes, LANES};

/// Random 64-bit patterns (splitmix64).
struct Bits(u64);

impl Bits {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    /// A double of random sign and mantissa, exponent in `lo ..= hi`.
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
    /// Uniform in [0, 1).
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Asserts every lane of `lanes(x)` has the bits of `one` (named `name`)
/// of that lane's argument.
fn same(name: &str, lanes: fn([f64; LANES]) -> [f64; LANES], one: fn(f64) -> f64, x: [f64; LANES]) {
    let got = lanes(x);
    for i in 0..LANES {
        let want = one(x[i]);
        assert!(
            got[i].to_bits() == want.to_bits() || (got[i].is_nan() && want.is_nan()),
            "lane {i}: {name}({:e}) ({:#x}) = {:e} ({:#x}), libm {:e} ({:#x})",
            x[i],
            x[i].to_bits(),
            got[i],
            got[i].to_bits(),
            want,
            want.to_bits()
        );
    }
}

/// Asserts every lane of `sin_lanes(x)` has `sin`'s bits.
fn check(x: [f64; LANES]) {
    same("sin", sin_lanes, sin, x);
}

#[test]
fn edges_and_special_values_in_any_lane_are_libm_s() {
    let pi = std::f64::consts::PI;
    let mut v = vec![
        0.0,
        f64::INFINITY,
        f64::NAN,
        f64::MIN_POSITIVE,
        f64::MAX,
        pi / 4.0,
        9.0 * pi / 4.0,
        2f64.powi(20) * pi / 2.0,
        1e-300,
        1e300,
    ];
    // musl's range edges and thresholds, as high words (2⁻²⁶, ~π/4,
    // ~3π/4, ~5π/4, ~7π/4, ~9π/4 and 2²⁰ π/2; the medium path's ~π/2, ~π,
    // ~3π/2 and ~2π), and multiples of π/2 (where the reduction cancels),
    // with their neighbours.
    for high in [
        0x3e50_0000u64,
        0x3e4f_ffff,
        0x3fe9_21fb,
        0x3fe9_21fc,
        0x3ff9_21fb,
        0x4002_d97c,
        0x4002_d97d,
        0x4009_21fb,
        0x400f_6a7a,
        0x400f_6a7b,
        0x4012_d97c,
        0x4015_fdbc,
        0x4015_fdbd,
        0x4019_21fb,
        0x401c_463b,
        0x401c_463c,
        0x4139_21fb,
        0x4139_21fa,
    ] {
        v.push(f64::from_bits(high << 32));
        v.push(f64::from_bits((high << 32) | 0xffff_ffff));
    }
    for k in 1..2000 {
        v.push(k as f64 * (pi / 2.0));
    }
    // Odd multiples of π/4 up to 9π/4, where the n musl takes from its
    // thresholds on the high word and the integer nearest x/(π/2) can
    // differ: a sweep of 2⁻³⁰ steps either side.
    for k in [1.0, 3.0, 5.0, 7.0, 9.0] {
        for j in -64..=64 {
            v.push(k * (pi / 4.0) * (1.0 + j as f64 * 2f64.powi(-30)));
        }
    }
    let edges = v.clone();
    for e in edges {
        if e.is_finite() && e > 0.0 {
            for d in 1..4 {
                v.push(f64::from_bits(e.to_bits() + d));
                v.push(f64::from_bits(e.to_bits() - d));
            }
        }
    }
    let negated: Vec<f64> = v.iter().map(|e| -e).collect();
    v.extend(negated);
    let ordinary = [10.0, -123.25, 5000.5, 77.0];
    for &x in &v {
        check([x; LANES]);
        for lane in 0..LANES {
            let mut xs = ordinary;
            xs[lane] = x;
            check(xs);
        }
    }
}

#[test]
fn ten_million_random_arguments_are_libm_s() {
    let mut r = Bits(2026);
    for k in 0..10_000_000 / LANES {
        let x: [f64; LANES] = match k % 3 {
            // An oscillator's 2π f t + phase: f up to 5 Hz, t up to 100 s.
            0 => std::array::from_fn(|_| {
                std::f64::consts::TAU * (5.0 * r.unit()) * (100.0 * r.unit())
                    + (r.unit() - 0.5) * std::f64::consts::TAU
            }),
            // Every binade past 9π/4 to 2^24.
            1 => std::array::from_fn(|_| r.spread(2, 24)),
            _ => std::array::from_fn(|_| r.spread(-30, 30)),
        };
        check(x);
    }
    // Random bit patterns: every exponent, NaNs and infinities included.
    for _ in 0..1_000_000 / LANES {
        check(std::array::from_fn(|_| f64::from_bits(r.next())));
    }
}

/// Asserts every lane of `exp_lanes(x)` has `exp`'s bits.
fn check_exp(x: [f64; LANES]) {
    same("exp", exp_lanes, exp, x);
}

#[test]
fn exp_at_the_edges_of_musl_s_ranges_and_at_random_is_libm_s() {
    // musl's range edges as high words (2^-28, ½ ln 2, 1.5 ln 2, 708.39),
    // with their neighbours, both signs, in every lane beside ordinary
    // arguments; then 10^7 random ones over every binade to 2^10 and
    // over a logistic output's inputs; then random bit patterns.
    let mut v = vec![0.0, f64::INFINITY, f64::NAN, 709.8, -745.2, 1e-300];
    for high in [0x3e30_0000u64, 0x3fd6_2e42, 0x3ff0_a2b2, 0x4086_232b] {
        for low in [0u64, 1, 0x7fff_ffff, 0xffff_fffe, 0xffff_ffff] {
            v.push(f64::from_bits((high << 32) | low));
            v.push(f64::from_bits(((high - 1) << 32) | low));
            v.push(f64::from_bits(((high + 1) << 32) | low));
        }
    }
    let negated: Vec<f64> = v.iter().map(|e| -e).collect();
    v.extend(negated);
    let ordinary = [0.7, -3.25, 12.5, -0.01];
    for &x in &v {
        check_exp([x; LANES]);
        for lane in 0..LANES {
            let mut xs = ordinary;
            xs[lane] = x;
            check_exp(xs);
        }
    }
    let mut r = Bits(11);
    for k in 0..10_000_000 / LANES {
        let x: [f64; LANES] = if k % 2 == 0 {
            std::array::from_fn(|_| r.spread(-30, 9))
        } else {
            std::array::from_fn(|_| 40.0 * (r.unit() - 0.5))
        };
        check_exp(x);
    }
    for _ in 0..1_000_000 / LANES {
        check_exp(std::array::from_fn(|_| f64::from_bits(r.next())));
    }
}
