//! # animats-gpu
//!
//! The per-creature step of animats written a second time, in C
//! (`kernel/step.h`), so that one GPU thread can step one creature of a
//! batch that holds any mix of bodies — and proven equal to the Rust
//! engine, bit for bit, by compiling the same C for the CPU (`build.rs`,
//! contraction off) and comparing it with [`animats_engine::World::step`]
//! on every test run (`tests/parity.rs`). The engine stays the one
//! definition of the physics: a change to it that the C does not follow
//! fails those tests.
//!
//! - [`Batch::pack`] lays worlds out as the C's structure of arrays with
//!   per-creature offsets, refusing (naming the world and the entry) what
//!   the C does not step yet.
//! - [`Batch::pack_scenes`] lays out whole scenes (sensors, actuators,
//!   brains, the `[evolve]` rules and measures) and
//!   [`Batch::evaluate_cpu`] / [`Device::evaluate`] evaluate them, with
//!   the evaluations `animats evaluate` gives, to the bit.
//! - [`Batch::run_cpu`] steps every creature with the C compiled for this
//!   CPU. [`Layout`] says where a thread keeps the creature's state.
//! - [`Device::open`] loads the NVIDIA driver and NVRTC at run time and
//!   compiles the same C for the GPU (a CUBIN for its architecture,
//!   `--fmad=false`); [`Device::run`] steps a batch there, one thread per
//!   creature. Where no driver, device or NVRTC is found, `open` says
//!   which. A batch of at least 4,096 creatures runs a kernel specialised
//!   for it ([`Special`]: its integrator, and only the parts its creatures
//!   have). Compiled kernels are kept on disk for the next run
//!   ([`cache`]). Run on an NVIDIA H200 with the CPU's bits (docs/GPU.md).
//!
//! What the C covers today: particles, uniform gravity, damped springs,
//! angle joints (with `atan2` ported from the `libm` crate, [`ported`]),
//! torque joints, constant forces, still fluids, the flat floor (collisions
//! located by backtracking, contact force), and the explicit integrators
//! (Euler, midpoint, RK4, symplectic Euler), soft contact between
//! spheres; for evaluations, `[[sensor]]`s, every actuator target,
//! oscillator, neural, CTRNN and FSM brains and the `[evolve]` fitness,
//! end rules and archive measures. docs/GPU.md says what is refused.

pub mod bodies;
pub mod cache;
pub mod cuda;
pub mod layout_choice;
pub mod order;
mod pack;
pub mod ported;
mod scenes;

pub use cuda::{Device, Schedule, Special, Tuning};
pub use scenes::cpu_has_fma;

/// How the C does its arithmetic.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Mode {
    /// As the engine: no fused multiply-add (the C compiled with
    /// contraction off, NVRTC given `--fmad=false`), so every result is
    /// the engine's to the bit. The default.
    #[default]
    Strict,
    /// Multiply-adds contracted into fused multiply-adds (NVRTC's
    /// `--fmad=true`; on the CPU, `kernel/fast.c` with FMA instructions):
    /// each rounds once where the strict mode rounds twice, so results
    /// drift from the engine's as a step's errors do; opt-in, checked by
    /// tolerance and by the ranking of a population ([`rank_correlation`];
    /// `tests/evaluate.rs`).
    Fast,
}
pub use pack::{Batch, Layout};
pub use scenes::{c_batches, c_runs};

/// Spearman's rank correlation of `a` and `b` (ties broken by index): how
/// alike two evaluations of one population rank it, the fast mode's check
/// against strict mode (1 for the same order).
pub fn rank_correlation(a: &[f64], b: &[f64]) -> f64 {
    let ranks = |x: &[f64]| {
        let mut order: Vec<usize> = (0..x.len()).collect();
        order.sort_by(|&i, &j| x[i].total_cmp(&x[j]).then(i.cmp(&j)));
        let mut r = vec![0.0; x.len()];
        for (rank, &i) in order.iter().enumerate() {
            r[i] = rank as f64;
        }
        r
    };
    let (ra, rb) = (ranks(a), ranks(b));
    let n = a.len() as f64;
    let d2: f64 = ra.iter().zip(&rb).map(|(x, y)| (x - y) * (x - y)).sum();
    1.0 - 6.0 * d2 / (n * (n * n - 1.0)).max(1.0)
}
