//! The build's CPU check: a program compiled for instructions the CPU lacks
//! refuses to start, naming them, before any of its own code runs.

use std::process::Command;

fn animats(lacks: Option<&str>) -> std::process::Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_animats"));
    cmd.arg("--version");
    match lacks {
        Some(l) => cmd.env("ANIMATS_TEST_CPU_LACKS", l),
        None => cmd.env_remove("ANIMATS_TEST_CPU_LACKS"),
    };
    cmd.output().expect("the animats binary runs")
}

#[test]
fn a_cpu_without_the_build_s_instructions_is_refused_by_name() {
    let needs = animats_engine::cpu::required_features();
    let ok = animats(None);
    assert!(ok.status.success(), "{ok:?}");
    assert!(String::from_utf8_lossy(&ok.stdout).starts_with("animats "));
    // The tests are built with the same flags as the program.
    assert_eq!(needs.contains("avx2"), cfg!(target_feature = "avx2"));
    let refused = animats(Some("popcnt,avx2,fma"));
    let err = String::from_utf8_lossy(&refused.stderr);
    if !needs.contains("avx2") {
        // A baseline build (RUSTFLAGS="-C target-cpu=x86-64") needs nothing.
        assert!(refused.status.success(), "{refused:?}");
        return;
    }
    assert_eq!(refused.status.code(), Some(2), "{refused:?}");
    assert!(refused.stdout.is_empty(), "nothing of the program ran");
    assert!(
        err.contains("(popcnt, avx2, fma)") && err.contains("target-cpu=native"),
        "{err}"
    );
    // A name the build does not use is not refused.
    let other = animats(Some("avx512f"));
    assert_eq!(
        other.status.success(),
        !needs.contains("avx512f"),
        "{other:?}"
    );
}
