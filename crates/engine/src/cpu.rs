//! The instruction set extensions this build was compiled to use, and the
//! check that refuses a CPU without them (`cpu_check.c`, linked by
//! `build.rs` and run before `main`).
//!
//! The workspace builds for x86-64-v3 (`.cargo/config.toml`): AVX2, FMA,
//! BMI2 and the rest, present in x86-64 CPUs since 2013–2015. Rust never
//! fuses a multiply and an add unless asked, and every operation keeps its
//! IEEE rounding at any vector width, so the results are the same bits as a
//! baseline build's (`RUSTFLAGS="-C target-cpu=x86-64"`), only sooner.

/// The extensions beyond the x86-64 baseline that this build uses, as
/// rustc names them (`"sse4.2,popcnt,avx,avx2,fma,bmi1,bmi2"` for
/// x86-64-v3), or `""` for a baseline build or another architecture.
pub fn required_features() -> &'static str {
    env!("ANIMATS_CPU_NEEDS")
}

/// Keeps the constructor's object in every program linked with the
/// engine: nothing else refers to it.
#[cfg(animats_cpu_check)]
mod keep {
    extern "C" {
        fn animats_cpu_check();
    }
    #[used]
    static CHECK: unsafe extern "C" fn() = animats_cpu_check;
}
