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
//! (A table-driven `atan2` of our own, twice musl's throughput in
//! isolation — 12.5 against 24.8 ns a call on an AMD EPYC — and as
//! accurate, gave the roobot's evaluation nothing: 2.32–2.43 ms against
//! 2.35 ms, the fastest of 30, 2026-11-27; the angle joints' `atan2`
//! overlaps the rest of the step. musl's own operations four joints at a
//! time, its branches turned into selections (every lane the same bits on
//! 10⁷ pairs), gave nothing either: 2.155 and 2.167 ms against 2.113 and
//! 2.033 ms, `animats bench hopper --runs 9`, 2026-11-30. So it is musl's.)

/// `sin x`.
#[inline]
pub fn sin(x: f64) -> f64 {
    libm::sin(x)
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
