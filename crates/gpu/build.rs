//! Compiles the C step (kernel/) for the CPU: contraction into fused
//! multiply-adds off, as the engine (Rust never contracts) and as NVRTC is
//! told (`--fmad=false`), so the three agree to the bit; and again in fast
//! mode (`kernel/fast.c`: contraction on, FMA instructions on x86-64), the
//! GPU's `--fmad=true` on the CPU.

fn main() {
    println!("cargo:rerun-if-changed=kernel/step.h");
    println!("cargo:rerun-if-changed=kernel/host.c");
    println!("cargo:rerun-if-changed=kernel/fast.c");
    println!("cargo:rerun-if-changed=kernel/libm.h");
    println!("cargo:rerun-if-changed=kernel/terrain.h");
    println!("cargo:rerun-if-changed=kernel/spheres.h");
    println!("cargo:rerun-if-changed=kernel/trig.h");
    println!("cargo:rerun-if-changed=kernel/eval.h");
    println!("cargo:rerun-if-changed=kernel/exp.h");
    cc::Build::new()
        .file("kernel/host.c")
        .flag_if_supported("-ffp-contract=off")
        .flag_if_supported("-fno-fast-math")
        .opt_level(2)
        .compile("animats_step");
    let mut fast = cc::Build::new();
    fast.file("kernel/fast.c")
        .flag_if_supported("-ffp-contract=fast")
        .flag_if_supported("-fno-fast-math")
        .opt_level(2);
    if std::env::var("CARGO_CFG_TARGET_ARCH").as_deref() == Ok("x86_64") {
        // (Called only where the CPU has FMA: src/scenes.rs checks.)
        fast.flag_if_supported("-mfma");
    }
    fast.compile("animats_step_fast");
}
