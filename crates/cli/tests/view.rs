//! `animats view` as a user starts and stops it.

mod common;
use common::{animats, text};
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, Command, Stdio};

/// The `host:port` in the `http://host:port/` that `text` prints.
fn address_in(text: &str) -> String {
    text.split("http://")
        .nth(1)
        .and_then(|s| s.split('/').next())
        .unwrap_or_else(|| panic!("no address in {text:?}"))
        .to_string()
}

/// The raw HTTP response to `GET path`.
fn get(address: &str, path: &str) -> String {
    let mut s = std::net::TcpStream::connect(address).expect("connect");
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {address}\r\nConnection: close\r\n\r\n"
    )
    .expect("write");
    let mut response = String::new();
    s.read_to_string(&mut response).expect("read");
    response
}

/// Sends Ctrl-C (SIGINT) to `child`.
fn ctrl_c(child: &Child) {
    Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
}

#[test]
fn it_prints_its_address_serves_the_page_and_stops_on_ctrl_c_with_a_summary() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_animats"))
        .args(["view", "scenes/seaworld.toml", "--port", "0"])
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start");
    let mut out = BufReader::new(child.stdout.take().expect("stdout"));
    let mut line = String::new();
    out.read_line(&mut line).expect("first line");
    let address = address_in(&line);
    assert!(
        address.starts_with("127.0.0.1:"),
        "binds this machine only by default: {line}"
    );

    let page = get(&address, "/");
    assert!(
        page.starts_with("HTTP/1.1 200") && page.contains("animats view"),
        "{page}"
    );

    ctrl_c(&child);
    let status = child.wait().expect("wait");
    let mut rest = String::new();
    out.read_to_string(&mut rest).expect("rest");
    assert_eq!(status.code(), Some(0), "{rest}");
    assert!(
        rest.contains("x real time"),
        "a summary with the real-time factor: {rest}"
    );
}

#[test]
fn a_missing_scene_or_a_port_in_use_exits_2() {
    let o = animats(&["view", "scenes/nope.toml", "--port", "0"]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("scenes/nope.toml"), "{err}");

    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let port = taken.local_addr().expect("address").port().to_string();
    let o = animats(&["view", "scenes/seaworld.toml", "--port", &port]);
    let (_, err) = text(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("cannot listen on 127.0.0.1:") && err.contains("--port"),
        "{err}"
    );
}

#[test]
fn evolve_view_serves_during_and_after_the_run_until_ctrl_c() {
    evolve_view("evolve-view", &["--generations", "20", "--lanes", "2"]);
}

/// A `[morphology]` run is watched too: its best body and brain.
#[test]
fn evolve_view_of_bodies_serves_during_and_after_the_run_until_ctrl_c() {
    let seen = evolve_view(
        "evolve-view-bodies",
        &["scenes/bodies_walk.toml", "--generations", "1"],
    );
    assert!(seen.contains("1 lanes, generation 1 of 1"), "{seen}");
}

/// Runs `animats evolve ARGS --view --port 0`, fetches the page after the
/// run, and stops the view with Ctrl-C; what the run printed.
fn evolve_view(name: &str, args: &[&str]) -> String {
    let dir = common::scratch(name);
    let mut child = Command::new(env!("CARGO_BIN_EXE_animats"))
        .arg("evolve")
        .args(args)
        .args(["--view", "--port", "0", "--out"])
        .arg(&dir)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start");
    let mut out = BufReader::new(child.stdout.take().expect("stdout"));
    let mut seen = String::new();
    let mut line = String::new();
    while out.read_line(&mut line).expect("line") > 0 {
        seen.push_str(&line);
        if line.contains("the view stays open") {
            break;
        }
        line.clear();
    }
    assert!(seen.contains("the view stays open"), "{seen}");
    let page = get(&address_in(&seen), "/app.js");
    assert!(
        page.starts_with("HTTP/1.1 200"),
        "served after the run: {page}"
    );
    ctrl_c(&child);
    let status = child.wait().expect("wait");
    assert_eq!(
        status.code(),
        Some(0),
        "the run had finished: Ctrl-C only closes the view"
    );
    assert!(dir.join("best.toml").exists());
    seen
}
