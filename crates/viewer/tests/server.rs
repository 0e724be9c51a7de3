//! The live server end to end over real sockets: what a browser sees, the
//! controls, and hostile clients (which must not disturb the others).

use animats_viewer::{Options, SceneStage, Server};
use futures_util::{SinkExt, StreamExt};
use serde_json::Value;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;
use tokio::net::TcpStream;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::{MaybeTlsStream, WebSocketStream};

type Socket = WebSocketStream<MaybeTlsStream<TcpStream>>;

fn seaworld() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/seaworld.toml")
}

/// A server on a free port, running SeaWorld; stopped on drop.
struct Live {
    url: String,
    stop: Arc<AtomicBool>,
    thread: Option<std::thread::JoinHandle<Result<animats_viewer::Summary, String>>>,
}

impl Live {
    fn start(max_clients: usize) -> Live {
        Live::on("127.0.0.1", max_clients).0
    }

    /// Serves on `host` (port 0); also returns the access token, if any.
    fn on(host: &str, max_clients: usize) -> (Live, Option<String>) {
        Live::scene(host, max_clients, seaworld())
    }

    /// Serves the scene at `path` on `host` (port 0).
    fn scene(host: &str, max_clients: usize, path: PathBuf) -> (Live, Option<String>) {
        let server = Server::bind(Options {
            host: host.into(),
            port: 0,
            max_clients,
            ..Options::default()
        })
        .expect("bind");
        let token = server.token().map(str::to_string);
        let port = server.address().expect("address").port();
        let url = format!("ws://127.0.0.1:{port}/ws");
        let stage = SceneStage::load(path).expect("scene");
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        let thread = Some(std::thread::spawn(move || server.serve(Box::new(stage), s)));
        (Live { url, stop, thread }, token)
    }
}

impl Drop for Live {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

async fn connect(url: &str) -> Socket {
    tokio_tungstenite::connect_async(url)
        .await
        .expect("connect")
        .0
}

/// The next JSON message, or None if the connection closed (10 s limit).
async fn next(ws: &mut Socket) -> Option<Value> {
    loop {
        let m = tokio::time::timeout(Duration::from_secs(10), ws.next())
            .await
            .ok()??;
        match m {
            Ok(Message::Text(t)) => return serde_json::from_str(t.as_str()).ok(),
            Ok(Message::Close(_)) | Err(_) => return None,
            Ok(_) => continue,
        }
    }
}

/// The next frame, skipping scene messages.
async fn frame(ws: &mut Socket) -> Value {
    loop {
        let m = next(ws).await.expect("a frame");
        if m["type"] == "frame" {
            return m;
        }
    }
}

/// The first frame sent after `f` holds.
async fn frame_where(ws: &mut Socket, f: impl Fn(&Value) -> bool) -> Value {
    for _ in 0..300 {
        let m = frame(ws).await;
        if f(&m) {
            return m;
        }
    }
    panic!("no such frame in 300");
}

async fn send(ws: &mut Socket, text: &str) {
    ws.send(Message::text(text)).await.expect("send");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_gets_the_scene_then_frames_of_every_particle() {
    let live = Live::start(4);
    let mut ws = connect(&live.url).await;
    let scene = next(&mut ws).await.expect("scene");
    assert_eq!(scene["type"], "scene");
    let n = scene["particles"].as_array().expect("particles").len();
    assert_eq!(n, 181, "SeaWorld has 181 particles");
    assert_eq!(scene["springs"].as_array().expect("springs").len(), 105);
    assert_eq!(scene["domes"].as_array().expect("domes").len(), 3);
    assert_eq!(scene["fluid"], 1000.0);
    assert_eq!(scene["food"], 0);
    let f = frame(&mut ws).await;
    assert_eq!(f["p"].as_array().expect("positions").len(), 3 * n);
    let states: Vec<&str> = f["creatures"]
        .as_array()
        .expect("creatures")
        .iter()
        .filter_map(|c| c["state"].as_str())
        .collect();
    assert_eq!(states.len(), 3, "three jellyfish report their FSM state");
    assert!(states
        .iter()
        .all(|s| ["idle", "track", "hover"].contains(s)));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pause_step_resume_speed_and_reset() {
    let live = Live::start(4);
    let mut ws = connect(&live.url).await;
    send(&mut ws, r#"{"cmd":"speed","value":4}"#).await;
    frame_where(&mut ws, |f| {
        f["speed"] == 4.0 && f["t"].as_f64().unwrap_or(0.0) > 0.5
    })
    .await;
    send(&mut ws, r#"{"cmd":"pause"}"#).await;
    let paused = frame_where(&mut ws, |f| f["paused"] == true).await;
    let t = paused["t"].as_f64().expect("t");
    for _ in 0..10 {
        assert_eq!(
            frame(&mut ws).await["t"].as_f64(),
            Some(t),
            "paused time stands still"
        );
    }
    send(&mut ws, r#"{"cmd":"step"}"#).await;
    let stepped = frame_where(&mut ws, |f| f["t"].as_f64() != Some(t)).await;
    let dt = stepped["t"].as_f64().expect("t") - t;
    assert!(
        (dt - 0.01).abs() < 1e-9,
        "one step is the scene's 10 ms, got {dt}"
    );
    send(&mut ws, r#"{"cmd":"resume"}"#).await;
    frame_where(&mut ws, |f| f["t"].as_f64().unwrap_or(0.0) > t + 1.0).await;
    send(&mut ws, r#"{"cmd":"reset"}"#).await;
    // A reset re-sends the scene and starts time again.
    loop {
        let m = next(&mut ws).await.expect("message");
        if m["type"] == "scene" {
            break;
        }
    }
    let f = frame(&mut ws).await;
    assert!(
        f["t"].as_f64().expect("t") < 0.5,
        "time restarts after a reset"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_food_moves_where_it_is_put() {
    let live = Live::start(4);
    let mut ws = connect(&live.url).await;
    let f0 = frame(&mut ws).await;
    let y = f0["p"][1].as_f64().expect("food y");
    send(&mut ws, r#"{"cmd":"food","x":0.6,"z":-0.4}"#).await;
    let f = frame_where(&mut ws, |f| {
        (f["p"][0].as_f64().unwrap_or(0.0) - 0.6).abs() < 1e-6
    })
    .await;
    assert!((f["p"][2].as_f64().expect("z") + 0.4).abs() < 1e-6);
    assert!(
        (f["p"][1].as_f64().expect("y") - y).abs() < 1e-3,
        "the food keeps its height"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn hostile_clients_are_ignored_or_dropped_and_others_keep_watching() {
    let live = Live::start(4);
    let mut good = connect(&live.url).await;
    frame(&mut good).await;

    // Garbage, wrong fields, unknown commands, binary, NaN-ish numbers: ignored.
    let mut bad = connect(&live.url).await;
    for text in [
        "hello",
        "{",
        r#"{"cmd":"explode"}"#,
        r#"{"cmd":"speed"}"#,
        r#"{"cmd":"speed","value":"fast"}"#,
        r#"{"cmd":"food","x":1e999,"z":0}"#,
        r#"{"cmd":"pause!"}"#,
        r#"{"type":"pause"}"#,
        "[1,2,3]",
    ] {
        send(&mut bad, text).await;
    }
    bad.send(Message::binary(vec![0u8, 159, 146, 150]))
        .await
        .expect("send");
    let f = frame(&mut bad).await;
    assert_eq!(f["paused"], false, "nothing above was obeyed");

    // A huge message closes that connection.
    let mut huge = connect(&live.url).await;
    let _ = huge.send(Message::text("x".repeat(1 << 20))).await;
    let mut closed = false;
    for _ in 0..100 {
        if next(&mut huge).await.is_none() {
            closed = true;
            break;
        }
    }
    assert!(closed, "a 1 MiB message closes the connection");

    // A stream of bad messages closes the connection.
    let mut noisy = connect(&live.url).await;
    for _ in 0..40 {
        if noisy.send(Message::text("nonsense")).await.is_err() {
            break;
        }
    }
    let mut closed = false;
    for _ in 0..100 {
        if next(&mut noisy).await.is_none() {
            closed = true;
            break;
        }
    }
    assert!(closed, "40 bad messages close the connection");

    // The good client never noticed.
    let t0 = frame(&mut good).await["t"].as_f64().expect("t");
    let t1 = frame_where(&mut good, |f| f["t"].as_f64().unwrap_or(0.0) > t0 + 0.2).await;
    assert_eq!(t1["paused"], false);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn clients_beyond_the_limit_are_refused_and_the_rest_watch() {
    let live = Live::start(2);
    let mut a = connect(&live.url).await;
    let mut b = connect(&live.url).await;
    frame(&mut a).await;
    frame(&mut b).await;
    match tokio_tungstenite::connect_async(&live.url).await {
        Err(tokio_tungstenite::tungstenite::Error::Http(r)) => assert_eq!(r.status(), 503),
        Err(e) => panic!("expected 503, got {e}"),
        Ok(_) => panic!("a third client was let in past the limit of 2"),
    }
    frame(&mut a).await;
    // A place frees up when a client leaves.
    drop(b);
    let mut c = None;
    for _ in 0..50 {
        if let Ok((ws, _)) = tokio_tungstenite::connect_async(&live.url).await {
            c = Some(ws);
            break;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    frame(c.as_mut().expect("a freed place")).await;
}

#[test]
fn a_port_in_use_is_a_clear_error() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").expect("bind");
    let port = taken.local_addr().expect("address").port();
    let e = Server::bind(Options {
        port,
        ..Options::default()
    })
    .err()
    .expect("the port is taken");
    assert!(
        e.contains(&format!("cannot listen on 127.0.0.1:{port}")),
        "{e}"
    );
    assert!(e.contains("--port"), "{e}");
}

/// GET `path` from the server whose WebSocket is at `ws_url`: (status line
/// and headers, body).
fn get(ws_url: &str, path: &str) -> (String, String) {
    use std::io::{Read, Write};
    let host = ws_url.trim_start_matches("ws://").trim_end_matches("/ws");
    let mut s = std::net::TcpStream::connect(host).expect("connect");
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .expect("write");
    let mut r = String::new();
    s.read_to_string(&mut r).expect("read");
    let (head, body) = r.split_once("\r\n\r\n").unwrap_or((&r, ""));
    (head.to_string(), body.to_string())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn off_the_loopback_address_the_page_and_socket_need_the_token() {
    // Bound to every interface (reached here through 127.0.0.1): a token.
    let (live, token) = Live::on("0.0.0.0", 4);
    let token = token.expect("a non-loopback host must require a token");
    assert_eq!(token.len(), 32);
    let url = live.url.clone();
    let heads = tokio::task::spawn_blocking({
        let token = token.clone();
        move || {
            ["/", "/?token=0123", "/?token=", &format!("/?token={token}")]
                .map(|path| get(&url, path).0)
        }
    })
    .await
    .expect("join");
    for head in &heads[..3] {
        assert!(head.starts_with("HTTP/1.1 403"), "{head}");
    }
    assert!(heads[3].starts_with("HTTP/1.1 200"), "{}", heads[3]);
    // The WebSocket: refused without the token (403), served with it.
    match tokio_tungstenite::connect_async(live.url.as_str()).await {
        Err(tokio_tungstenite::tungstenite::Error::Http(response)) => {
            assert_eq!(response.status(), 403)
        }
        Err(e) => panic!("refused, but not with 403: {e}"),
        Ok(_) => panic!("a WebSocket without the token was accepted"),
    }
    let mut ws = connect(&format!("{}?token={token}", live.url)).await;
    let scene = next(&mut ws).await.expect("the scene");
    assert_eq!(scene["type"], "scene");
    // The page draws with the renderer's palette, which the scene carries.
    for (kind, colour) in animats_view::palette::PALETTE {
        assert_eq!(scene["palette"][kind], colour, "{kind}");
    }
    // On the loopback address there is none.
    let (_local, none) = Live::on("127.0.0.1", 1);
    assert!(none.is_none());
}

#[test]
fn the_page_and_three_js_are_served_from_the_binary() {
    let live = Live::start(2);
    let get = |path: &str| get(&live.url, path);
    let (head, body) = get("/");
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    assert!(
        body.contains("\"three\": \"/vendor/three.module.js\""),
        "the page maps three.js to the embedded copy"
    );
    for path in [
        "/app.js",
        "/vendor/three.module.js",
        "/vendor/three.core.js",
        "/vendor/OrbitControls.js",
    ] {
        let (head, _) = get(path);
        assert!(head.starts_with("HTTP/1.1 200"), "{path}: {head}");
        assert!(
            head.to_lowercase()
                .contains("content-type: text/javascript"),
            "{path}: {head}"
        );
    }
    assert!(get("/vendor/../../etc/passwd")
        .0
        .starts_with("HTTP/1.1 404"));
    assert!(get("/nothing").0.starts_with("HTTP/1.1 404"));
}

/// Nothing is simulated before the first tab connects (a hopping roobot
/// would be gone before anyone saw it), and the frames carry the walker's
/// centre for the page's camera to follow.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_view_waits_for_its_first_tab_and_follows_the_walker() {
    let roobot = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scenes/roobot.toml");
    let (live, _) = Live::scene("127.0.0.1", 4, roobot);
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let mut ws = connect(&live.url).await;
    let scene = next(&mut ws).await.expect("the scene");
    assert_eq!(scene["type"], "scene");
    assert_eq!(scene["orbit"], false);
    let first = frame(&mut ws).await;
    let t = first["t"].as_f64().unwrap();
    assert!(
        t < 0.5,
        "1.5 s passed before the tab connected, and the run is at t = {t}"
    );
    let x0 = first["focus"][0].as_f64().expect("a focus to follow");
    let later = frame_where(&mut ws, |f| f["t"].as_f64().unwrap_or(0.0) > 2.0).await;
    let x1 = later["focus"][0].as_f64().unwrap();
    // The evolved gait travels about 2 m/s along +x.
    assert!(x1 - x0 > 1.0, "the focus moved from x = {x0} to {x1}");
}

/// A 64 × 64 net of 1 g beads on springs hanging from two corners: 4,096
/// particles, a world that splits its work over threads, whose live loop
/// runs on the thread pool (`Runner::step_while`).
fn net_scene() -> PathBuf {
    let side = 64;
    let mut s = String::from(
        "[world]\ngravity = [0, -9.8, 0]\nintegrator = \"symplectic\"\ndt = 0.0001\n\n",
    );
    let name = |i: usize, j: usize| format!("p{i}_{j}");
    for i in 0..side {
        for j in 0..side {
            s += &format!(
                "[[particle]]\nname = \"{}\"\nmass = 0.001\nradius = 0.002\nposition = [{}, {}, 0]\nfixed = {}\n\n",
                name(i, j),
                0.01 * i as f64,
                1.0 + 0.01 * j as f64,
                j == side - 1 && (i == 0 || i == side - 1)
            );
        }
    }
    for i in 0..side {
        for j in 0..side {
            for (k, l) in [(i + 1, j), (i, j + 1)] {
                if k < side && l < side {
                    s += &format!(
                        "[[spring]]\na = \"{}\"\nb = \"{}\"\nstiffness = 10\ndamping = 0.001\n\n",
                        name(i, j),
                        name(k, l)
                    );
                }
            }
        }
    }
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("live_net.toml");
    std::fs::write(&path, s).expect("write the scene");
    path
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_large_world_plays_live_and_sags_under_gravity() {
    let (live, _) = Live::scene("127.0.0.1", 4, net_scene());
    let mut ws = connect(&live.url).await;
    let scene = next(&mut ws).await.expect("scene");
    assert_eq!(
        scene["particles"].as_array().expect("particles").len(),
        4096
    );
    let first = frame(&mut ws).await;
    let lowest = |f: &Value| {
        f["p"]
            .as_array()
            .expect("positions")
            .chunks(3)
            .map(|p| p[1].as_f64().expect("a finite y"))
            .fold(f64::INFINITY, f64::min)
    };
    let y0 = lowest(&first);
    // Flat out, then wait until 20 ms have been simulated.
    send(&mut ws, r#"{"cmd":"speed","value":0}"#).await;
    let later = frame_where(&mut ws, |f| f["t"].as_f64().unwrap_or(0.0) > 0.02).await;
    assert!(later["error"].is_null(), "{later}");
    let y1 = lowest(&later);
    // Free fall for 20 ms drops the loose bottom row by about g t²/2 ≈ 2 mm.
    assert!(y1 < y0 - 1e-3, "the net sags: lowest y {y0} -> {y1}");
}
