//! Links `src/cpu_check.c` into every program built on the engine when
//! rustc was told to use x86-64 instructions beyond the baseline (the
//! workspace's `.cargo/config.toml` asks for x86-64-v3): a constructor that
//! refuses, with a message, a CPU that lacks them. A baseline build (as a
//! crate built elsewhere gets) links nothing.

fn main() {
    println!("cargo:rerun-if-changed=src/cpu_check.c");
    println!("cargo::rustc-check-cfg=cfg(animats_cpu_check)");
    let var = |k: &str| std::env::var(k).unwrap_or_default();
    // The constructor needs GCC's or Clang's `__builtin_cpu_supports`.
    if var("CARGO_CFG_TARGET_ARCH") != "x86_64" || var("CARGO_CFG_TARGET_FAMILY") != "unix" {
        println!("cargo:rustc-env=ANIMATS_CPU_NEEDS=");
        return;
    }
    let features = var("CARGO_CFG_TARGET_FEATURE");
    let features: Vec<&str> = features.split(',').collect();
    // rustc's names beyond the x86-64 baseline that the check knows, with
    // `__builtin_cpu_supports`'s for each.
    let known = [
        ("sse4.2", "sse4.2"),
        ("popcnt", "popcnt"),
        ("avx", "avx"),
        ("avx2", "avx2"),
        ("fma", "fma"),
        ("bmi1", "bmi"),
        ("bmi2", "bmi2"),
        ("avx512f", "avx512f"),
    ];
    let needs: Vec<(&str, &str)> = known
        .into_iter()
        .filter(|(rustc, _)| features.contains(rustc))
        .collect();
    let names: Vec<&str> = needs.iter().map(|(rustc, _)| *rustc).collect();
    println!("cargo:rustc-env=ANIMATS_CPU_NEEDS={}", names.join(","));
    if needs.is_empty() {
        return;
    }
    // The C checks each in this order: `CHECK("avx") CHECK("avx2") …`.
    let checks: Vec<String> = needs
        .iter()
        .map(|(_, gcc)| format!("CHECK(\"{gcc}\")"))
        .collect();
    cc::Build::new()
        .file("src/cpu_check.c")
        // The check itself must run on any x86-64.
        .flag("-march=x86-64")
        .flag("-mtune=generic")
        .opt_level(2)
        .define("ANIMATS_CHECKS", checks.join(" ").as_str())
        .compile("animats_cpu_check");
    println!("cargo:rustc-cfg=animats_cpu_check");
}
