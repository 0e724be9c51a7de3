//! Which vector instructions the hot loops are compiled for, chosen once
//! at run time from the CPU (a binary users install cannot assume the
//! build machine's CPU).
//!
//! Two kinds of loop choose separately:
//! - [`Use::Arithmetic`]: the springs' blocks and the n-body pairs,
//!   long runs of square roots, divisions and products on separate arrays;
//! - [`Use::Updates`]: the integrators' flat updates and the finiteness
//!   scan, a few additions per coordinate, short and memory-bound.
//!
//! Every path gives the same bits (each element gets the same operations
//! in the same order, nothing fused; the tests of each loop compare them),
//! so the choice changes speed only, never a result.
//!
//! The policy comes from measurements (2026-11-25, in the git log): on the AMD EPYC (Zen 4) the widest vectors
//! were fastest for both kinds; on the Intel Xeon, 256-bit vectors beat
//! 512-bit ones for the arithmetic (cloth-128's force evaluations 293–297
//! against 332–333 ms) and the baseline's SSE2 beat both for the updates
//! (cloth-128 on two threads 247–260 ms against 335–338 ms with AVX-512:
//! a core that wakes for a piece of wide work runs it slowly at first).
//! Hence: AVX-512 where the CPU has it, except on Intel, where the
//! arithmetic takes AVX2 and the updates the build's baseline: SSE2 then,
//! AVX2 since the workspace builds for x86-64-v3 (not yet measured on
//! the Xeon).
//!
//! `ANIMATS_SIMD=base|avx2|avx512` caps both (an unknown value caps
//! nothing), to compare paths or to sidestep a CPU's slow one.

use std::sync::OnceLock;

/// An instruction set a loop can be compiled for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Width {
    /// What the build targets: on x86-64 the workspace's x86-64-v3 (AVX2,
    /// `.cargo/config.toml`), or the baseline SSE2 in a baseline build;
    /// whatever the target has elsewhere.
    Base,
    /// AVX2: four f64 a vector.
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// AVX-512F: eight f64 a vector.
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl Width {
    /// Every width this CPU can run, narrowest first.
    pub(crate) fn available() -> Vec<Width> {
        #[allow(unused_mut)] // only x86-64 adds to it
        let mut all = vec![Width::Base];
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx2") {
                all.push(Width::Avx2);
            }
            if std::arch::is_x86_feature_detected!("avx512f") {
                all.push(Width::Avx512);
            }
        }
        all
    }

    /// The name `ANIMATS_SIMD` takes.
    pub(crate) fn name(self) -> &'static str {
        match self {
            Width::Base if cfg!(all(target_arch = "x86_64", not(target_feature = "avx"))) => "sse2",
            Width::Base => "base",
            #[cfg(target_arch = "x86_64")]
            Width::Avx2 => "avx2",
            #[cfg(target_arch = "x86_64")]
            Width::Avx512 => "avx512",
        }
    }
}

/// What a loop does, for [`width`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Use {
    /// Many divisions, square roots and products per element.
    Arithmetic,
    /// A few additions per element: the integrators' updates, the scan.
    Updates,
}

/// The instruction set loops of kind `u` use on this CPU: one the CPU has.
#[inline]
pub(crate) fn width(u: Use) -> Width {
    static CHOSEN: OnceLock<[Width; 2]> = OnceLock::new();
    let chosen = CHOSEN.get_or_init(|| {
        let cap = std::env::var("ANIMATS_SIMD").ok();
        choose(&Width::available(), is_intel(), cap.as_deref())
    });
    match u {
        Use::Arithmetic => chosen[0],
        Use::Updates => chosen[1],
    }
}

/// The policy: `[arithmetic, updates]` from the widths the CPU has
/// (narrowest first, the baseline always), whether it is Intel's, and
/// `ANIMATS_SIMD`.
fn choose(available: &[Width], intel: bool, cap: Option<&str>) -> [Width; 2] {
    let widest = available.iter().copied().max().unwrap_or(Width::Base);
    let limit = match cap {
        Some("base" | "sse2") => Width::Base,
        #[cfg(target_arch = "x86_64")]
        Some("avx2") => Width::Avx2,
        _ => widest,
    };
    let pick = |want: Width| {
        available
            .iter()
            .copied()
            .filter(|&w| w <= want.min(limit))
            .max()
            .unwrap_or(Width::Base)
    };
    #[cfg(target_arch = "x86_64")]
    if intel {
        return [pick(Width::Avx2), pick(Width::Base)];
    }
    let _ = intel;
    [pick(widest), pick(widest)]
}

/// Whether the CPU is Intel's (CPUID's vendor string).
fn is_intel() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        // (CPUID leaf 0 exists on every x86-64 CPU.)
        let r = std::arch::x86_64::__cpuid(0);
        let vendor: Vec<u8> = [r.ebx, r.edx, r.ecx]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        vendor == b"GenuineIntel"
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// Which instruction sets this process's loops use, for benchmark
/// records: e.g. `arithmetic avx2, updates sse2`.
pub fn summary() -> String {
    format!(
        "arithmetic {}, updates {}",
        width(Use::Arithmetic).name(),
        width(Use::Updates).name()
    )
}

/// Calls `body` compiled for the instruction set loops of kind `u` use
/// ([`width`]). `body` must be an `#[inline(always)]` closure, or it is
/// compiled for the baseline alone.
#[inline(always)]
pub(crate) fn chosen<R>(u: Use, body: impl FnOnce() -> R) -> R {
    on(width(u), body)
}

/// Calls `body` compiled for `width`, or for the widest narrower
/// instruction set this CPU has.
#[inline(always)]
pub(crate) fn on<R>(width: Width, body: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx512f")]
        unsafe fn avx512<R>(body: impl FnOnce() -> R) -> R {
            body()
        }
        #[target_feature(enable = "avx2")]
        unsafe fn avx2<R>(body: impl FnOnce() -> R) -> R {
            body()
        }
        if width == Width::Avx512 && std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the CPU has AVX-512F (checked just above).
            return unsafe { avx512(body) };
        }
        if width != Width::Base && std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2 (checked just above).
            return unsafe { avx2(body) };
        }
    }
    let _ = width;
    body()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn intel_takes_avx2_for_arithmetic_and_sse2_for_updates_others_the_widest() {
        let all = [Width::Base, Width::Avx2, Width::Avx512];
        assert_eq!(choose(&all, true, None), [Width::Avx2, Width::Base]);
        assert_eq!(choose(&all, false, None), [Width::Avx512, Width::Avx512]);
        // A CPU without AVX-512, and one with nothing past the baseline.
        assert_eq!(choose(&all[..2], true, None), [Width::Avx2, Width::Base]);
        assert_eq!(choose(&all[..2], false, None), [Width::Avx2, Width::Avx2]);
        assert_eq!(choose(&all[..1], false, None), [Width::Base, Width::Base]);
        assert_eq!(choose(&all[..1], true, None), [Width::Base, Width::Base]);
    }

    #[test]
    #[cfg(target_arch = "x86_64")]
    fn animats_simd_caps_both_and_never_asks_for_what_the_cpu_lacks() {
        let all = [Width::Base, Width::Avx2, Width::Avx512];
        let base = [Width::Base, Width::Base];
        assert_eq!(
            choose(&all, false, Some("avx2")),
            [Width::Avx2, Width::Avx2]
        );
        assert_eq!(choose(&all, false, Some("base")), base);
        assert_eq!(choose(&all, false, Some("sse2")), base);
        assert_eq!(choose(&all, true, Some("base")), base);
        // A cap above the CPU's widest, or an unknown word, caps nothing.
        assert_eq!(
            choose(&all[..2], false, Some("avx512")),
            [Width::Avx2, Width::Avx2]
        );
        assert_eq!(
            choose(&all, false, Some("fast")),
            [Width::Avx512, Width::Avx512]
        );
        // The cap does not raise Intel's choice.
        assert_eq!(
            choose(&all, true, Some("avx512")),
            [Width::Avx2, Width::Base]
        );
    }

    #[test]
    fn the_chosen_widths_are_ones_this_cpu_has() {
        let all = Width::available();
        assert!(all.contains(&width(Use::Arithmetic)));
        assert!(all.contains(&width(Use::Updates)));
        assert!(summary().starts_with("arithmetic "));
    }
}
