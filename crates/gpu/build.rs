//! Compiles the C step (kernel/) for the CPU: contraction into fused
//! multiply-adds off, as the engine (Rust never contracts) and as NVRTC is
//! told (`--fmad=false`), so the three agree to the bit.

fn main() {
    println!("cargo:rerun-if-changed=kernel/step.h");
    println!("cargo:rerun-if-changed=kernel/host.c");
    println!("cargo:rerun-if-changed=kernel/libm.h");
    println!("cargo:rerun-if-changed=kernel/terrain.h");
    println!("cargo:rerun-if-changed=kernel/trig.h");
    println!("cargo:rerun-if-changed=kernel/eval.h");
    println!("cargo:rerun-if-changed=kernel/exp.h");
    cc::Build::new()
        .file("kernel/host.c")
        .flag_if_supported("-ffp-contract=off")
        .flag_if_supported("-fno-fast-math")
        .opt_level(2)
        .compile("animats_step");
}
