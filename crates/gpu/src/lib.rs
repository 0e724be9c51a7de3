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
//! - [`Batch::run_cpu`] steps every creature with the C compiled for this
//!   CPU.
//! - [`Device::open`] loads the NVIDIA driver and NVRTC at run time and
//!   compiles the same C for the GPU (a CUBIN for its architecture,
//!   `--fmad=false`); [`Device::run`] steps a batch there, one thread per
//!   creature. Where no driver, device or NVRTC is found, `open` says
//!   which. Run on an NVIDIA H200 with the CPU's bits (docs/GPU.md).
//!
//! What the C covers today: particles, uniform gravity, damped springs,
//! angle joints (with `atan2` ported from the `libm` crate, [`ported`]),
//! torque joints, constant forces, still fluids, the flat floor (collisions
//! located by backtracking, contact force), and the explicit integrators
//! (Euler, midpoint, RK4, symplectic Euler). Sensors, brains and fitness
//! are issue 42's next steps; docs/GPU.md says where it stands.

pub mod bodies;
pub mod cuda;
mod pack;
pub mod ported;
mod scenes;

pub use cuda::Device;
pub use pack::Batch;
pub use scenes::{c_batches, c_runs};
