//! The web server: the page, its scripts, and one WebSocket per watching tab.
//!
//! Hostile input is bounded: a message longer than [`MAX_MESSAGE`] bytes
//! closes that connection, so does a client that keeps sending what is not a
//! command ([`MAX_STRIKES`]) or sends faster than [`MAX_COMMANDS_PER_S`];
//! at most `max_clients` tabs watch at once (the next is refused with 503).
//! Other clients never notice.

use crate::protocol::Command;
use crate::runner::Outlets;
use axum::extract::ws::{Message, Utf8Bytes, WebSocket, WebSocketUpgrade};
use axum::extract::{Path, RawQuery, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::Sender;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Largest message a client may send, bytes (commands are tens of bytes).
pub const MAX_MESSAGE: usize = 4096;
/// Malformed messages a client may send before it is disconnected.
pub const MAX_STRIKES: u32 = 20;
/// Commands a client may send per second before it is disconnected.
pub const MAX_COMMANDS_PER_S: u32 = 100;
/// A client that cannot take a frame for this long is disconnected.
const SEND_TIMEOUT: Duration = Duration::from_secs(10);

const INDEX_HTML: &str = include_str!("../web/index.html");
const APP_JS: &str = include_str!("../web/app.js");
const THREE_MODULE: &str = include_str!("../web/vendor/three.module.js");
const THREE_CORE: &str = include_str!("../web/vendor/three.core.js");
const ORBIT_CONTROLS: &str = include_str!("../web/vendor/OrbitControls.js");

/// What every request handler shares.
#[derive(Clone)]
pub struct App {
    /// Where the runner publishes.
    pub out: Outlets,
    /// Commands to the runner.
    pub commands: Sender<Command>,
    /// Connected WebSocket clients.
    pub clients: Arc<AtomicUsize>,
    /// At most this many at once.
    pub max_clients: usize,
    /// The access token the page and the WebSocket must show, if any.
    pub token: Option<Arc<str>>,
}

fn forbidden() -> Response {
    (
        StatusCode::FORBIDDEN,
        "this view needs the access token printed with its address (…/?token=…)",
    )
        .into_response()
}

/// The routes: `/` (the page), `/app.js`, `/vendor/*` (three.js), `/ws`.
pub fn router(app: App) -> Router {
    Router::new()
        .route("/", get(index))
        .route("/app.js", get(|| async { page(JS, APP_JS) }))
        .route("/vendor/{file}", get(vendor))
        .route("/ws", get(upgrade))
        .with_state(app)
}

const JS: &str = "text/javascript; charset=utf-8";

async fn index(State(app): State<App>, RawQuery(query): RawQuery) -> Response {
    if !crate::access::allowed(app.token.as_deref(), query.as_deref()) {
        return forbidden();
    }
    page("text/html; charset=utf-8", INDEX_HTML)
}

fn page(content_type: &'static str, body: &'static str) -> Response {
    ([(header::CONTENT_TYPE, content_type)], body).into_response()
}

async fn vendor(Path(file): Path<String>) -> Response {
    match file.as_str() {
        "three.module.js" => page(JS, THREE_MODULE),
        "three.core.js" => page(JS, THREE_CORE),
        "OrbitControls.js" => page(JS, ORBIT_CONTROLS),
        _ => (StatusCode::NOT_FOUND, "not found").into_response(),
    }
}

/// Holds one of the `max_clients` places until dropped.
struct Place(Arc<AtomicUsize>);

impl Drop for Place {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

async fn upgrade(
    State(app): State<App>,
    RawQuery(query): RawQuery,
    ws: WebSocketUpgrade,
) -> Response {
    if !crate::access::allowed(app.token.as_deref(), query.as_deref()) {
        eprintln!("viewer: refused a client without the access token");
        return forbidden();
    }
    if app.clients.fetch_add(1, Ordering::SeqCst) >= app.max_clients {
        app.clients.fetch_sub(1, Ordering::SeqCst);
        eprintln!(
            "viewer: refused a client: already {} watching",
            app.max_clients
        );
        return (StatusCode::SERVICE_UNAVAILABLE, "too many viewers").into_response();
    }
    let place = Place(app.clients.clone());
    ws.max_message_size(MAX_MESSAGE)
        .max_frame_size(MAX_MESSAGE)
        .on_upgrade(move |socket| watch(socket, app, place))
}

async fn send(socket: &mut WebSocket, text: Utf8Bytes) -> bool {
    matches!(
        tokio::time::timeout(SEND_TIMEOUT, socket.send(Message::Text(text))).await,
        Ok(Ok(()))
    )
}

/// One client: the scene, then frames as they come; its commands to the
/// runner.
async fn watch(mut socket: WebSocket, app: App, _place: Place) {
    let mut scene = app.out.scene.subscribe();
    let mut frames = app.out.frames.subscribe();
    let first = scene.borrow_and_update().clone();
    if !send(&mut socket, first).await {
        return;
    }
    let mut strikes = 0u32;
    let mut window = (Instant::now(), 0u32);
    loop {
        tokio::select! {
            // A new scene (after a reset) goes first, and any frame of the
            // old one still waiting is dropped.
            biased;
            changed = scene.changed() => {
                let text = scene.borrow_and_update().clone();
                frames.borrow_and_update();
                if changed.is_err() || !send(&mut socket, text).await {
                    break;
                }
            }
            changed = frames.changed() => {
                let text = frames.borrow_and_update().clone();
                if changed.is_err() || !send(&mut socket, text).await {
                    break;
                }
            }
            message = socket.recv() => {
                let text = match message {
                    None | Some(Ok(Message::Close(_))) => break,
                    Some(Err(e)) => {
                        eprintln!("viewer: closing a connection: {e}");
                        break;
                    }
                    Some(Ok(Message::Text(text))) => text,
                    Some(Ok(Message::Binary(_))) => {
                        strikes += 1;
                        eprintln!("viewer: ignored a binary message");
                        continue;
                    }
                    // Pings are answered by the library.
                    Some(Ok(_)) => continue,
                };
                if window.0.elapsed() >= Duration::from_secs(1) {
                    window = (Instant::now(), 0);
                }
                window.1 += 1;
                if window.1 > MAX_COMMANDS_PER_S {
                    eprintln!("viewer: closing a connection: more than {MAX_COMMANDS_PER_S} messages a second");
                    break;
                }
                match serde_json::from_str::<Command>(text.as_str()) {
                    Ok(command) => {
                        if app.commands.send(command).is_err() {
                            break;
                        }
                    }
                    Err(e) => {
                        strikes += 1;
                        eprintln!("viewer: ignored a message that is not a command: {e}");
                    }
                }
            }
        }
        if strikes > MAX_STRIKES {
            eprintln!("viewer: closing a connection after {MAX_STRIKES} bad messages");
            break;
        }
    }
    let _ = socket.send(Message::Close(None)).await;
}
