//! Helpers for tests that run the `animats` binary.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A fresh directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The `animats` binary, to be run in the repository root: for tests that
/// set its environment too.
pub fn command() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_animats"));
    c.current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    c
}

/// Runs `animats` with `args` in the repository root.
pub fn animats(args: &[&str]) -> Output {
    command().args(args).output().expect("run animats")
}

/// Stdout and stderr as text.
pub fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

/// Writes a file and returns its path as a string.
pub fn write(dir: &Path, name: &str, contents: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, contents).unwrap();
    p.to_string_lossy().into_owned()
}

/// A scene that blows up: a stiff spring and a huge step under explicit
/// Euler, so the amplitude grows by about ωh ≈ 300 per step and overflows
/// within a few hundred steps; the particle to blame is `wobbly`.
pub const STIFF_SCENE: &str = r#"
[world]
gravity = [0.0, 0.0, 0.0]
dt = 0.01
integrator = "euler"
duration = 100.0

[[particle]]
name = "anchor"
mass = 1.0
position = [0.0, 0.0, 0.0]
radius = 0.01
fixed = true

[[particle]]
name = "wobbly"
mass = 0.001
position = [1.1, 0.0, 0.0]
radius = 0.01

[[spring]]
a = "anchor"
b = "wobbly"
stiffness = 1e6
rest_length = 1.0
"#;

/// Runs `animats` with `args` for at most `seconds`: its output, or
/// `None` (the run killed) if it had not ended by then.
pub fn animats_within(args: &[&str], seconds: u64) -> Option<Output> {
    let mut child = command()
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run animats");
    let began = std::time::Instant::now();
    while child.try_wait().expect("wait for animats").is_none() {
        if began.elapsed().as_secs() > seconds {
            let _ = child.kill();
            let _ = child.wait();
            return None;
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    Some(child.wait_with_output().expect("animats's output"))
}
