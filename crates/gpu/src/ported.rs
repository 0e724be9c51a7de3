//! The C port of the step's transcendental functions (`kernel/libm.h`,
//! `kernel/trig.h`, `kernel/exp.h`),
//! callable from Rust so its tests can hold it to the `libm` crate's bits.

use std::os::raw::c_double;

extern "C" {
    fn animats_atan(x: c_double) -> c_double;
    fn animats_atan2(y: c_double, x: c_double) -> c_double;
    fn animats_hypot(x: c_double, y: c_double) -> c_double;
    fn animats_asin(x: c_double) -> c_double;
    fn animats_sin(x: c_double) -> c_double;
    fn animats_cos(x: c_double) -> c_double;
    fn animats_exp(x: c_double) -> c_double;
    fn animats_expm1(x: c_double) -> c_double;
    fn animats_tanh(x: c_double) -> c_double;
}

/// `e^x` as the C step computes it.
pub fn exp(x: f64) -> f64 {
    // SAFETY: a pure function of its argument.
    unsafe { animats_exp(x) }
}

/// `e^x − 1` as the C step computes it.
pub fn expm1(x: f64) -> f64 {
    // SAFETY: a pure function of its argument.
    unsafe { animats_expm1(x) }
}

/// `tanh x` as the C step computes it.
pub fn tanh(x: f64) -> f64 {
    // SAFETY: a pure function of its argument.
    unsafe { animats_tanh(x) }
}

/// `sin x` as the C step computes it.
pub fn sin(x: f64) -> f64 {
    // SAFETY: a pure function of its argument.
    unsafe { animats_sin(x) }
}

/// `cos x` as the C step computes it.
pub fn cos(x: f64) -> f64 {
    // SAFETY: a pure function of its argument.
    unsafe { animats_cos(x) }
}

/// `atan x` as the C step computes it.
pub fn atan(x: f64) -> f64 {
    // SAFETY: a pure function of its argument.
    unsafe { animats_atan(x) }
}

/// `atan2(y, x)` as the C step computes it.
pub fn atan2(y: f64, x: f64) -> f64 {
    // SAFETY: a pure function of its arguments.
    unsafe { animats_atan2(y, x) }
}

/// `hypot(x, y)` as the C step computes it (a jellyfish's food sense).
pub fn hypot(x: f64, y: f64) -> f64 {
    // SAFETY: a pure function of its arguments.
    unsafe { animats_hypot(x, y) }
}

/// `asin x` as the C step computes it (Raibert's foot placement).
pub fn asin(x: f64) -> f64 {
    // SAFETY: a pure function of its argument.
    unsafe { animats_asin(x) }
}
