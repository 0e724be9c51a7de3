//! Live 3D view of animats worlds in the browser.
//!
//! `animats view` binds a web server (127.0.0.1 unless told otherwise),
//! serves a page that draws with three.js (vendored and embedded: the
//! browser needs no network), and streams the world over a WebSocket at the
//! display rate while a thread of its own runs the simulation.
//!
//! - `protocol.rs`: the JSON messages;
//! - `animats-view` (a crate below this one and the renderer): what is run
//!   and drawn; `exhibition.rs`: an evolution's exhibition stage (its best
//!   brain so far);
//! - `runner.rs`: the simulation thread, pacing and commands;
//! - `server.rs`: routes, the WebSocket, and the bounds on hostile clients;
//! - `access.rs`: the access token required off the loopback address;
//! - `web/`: the page (`index.html`, `app.js`) and three.js.

#![warn(missing_docs)]

pub mod access;
pub mod exhibition;
pub mod protocol;
pub mod runner;
pub mod server;
pub use animats_view::stage;

pub use animats_view::{SceneStage, Stage};
pub use exhibition::{BestBrain, Exhibition};

pub use runner::Summary;
use runner::{Outlets, Runner};
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// How to serve.
#[derive(Clone, Debug)]
pub struct Options {
    /// Address to bind (127.0.0.1: this machine only).
    pub host: String,
    /// Port (0: any free port).
    pub port: u16,
    /// Frames streamed per second.
    pub display_hz: f64,
    /// Real-time factor to start at; 0 is flat out.
    pub speed: f64,
    /// Most WebSocket clients at once.
    pub max_clients: usize,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            host: "127.0.0.1".into(),
            port: 8080,
            display_hz: 30.0,
            speed: 1.0,
            max_clients: 16,
        }
    }
}

/// A bound server, not yet serving.
pub struct Server {
    listener: std::net::TcpListener,
    options: Options,
    token: Option<String>,
}

impl Server {
    /// Binds the address; a port in use is a clear error.
    pub fn bind(options: Options) -> Result<Server, String> {
        let address = format!("{}:{}", options.host, options.port);
        let listener = std::net::TcpListener::bind(&address).map_err(|e| {
            let hint = if e.kind() == std::io::ErrorKind::AddrInUse {
                "; another program is using that port: choose another with --port (0 picks a free one)"
            } else {
                ""
            };
            format!("cannot listen on {address}: {e}{hint}")
        })?;
        listener
            .set_nonblocking(true)
            .map_err(|e| format!("cannot listen on {address}: {e}"))?;
        // Off the loopback address anyone who can reach the port could
        // steer the run: require a token.
        let token = (!access::is_loopback(&options.host)).then(access::new_token);
        Ok(Server {
            listener,
            options,
            token,
        })
    }

    /// The address it listens on.
    pub fn address(&self) -> Result<SocketAddr, String> {
        self.listener.local_addr().map_err(|e| e.to_string())
    }

    /// The access token the page and WebSocket require (none on a loopback
    /// address).
    pub fn token(&self) -> Option<&str> {
        self.token.as_deref()
    }

    /// The page's URL, with the token when one is required.
    pub fn url(&self) -> Result<String, String> {
        let address = self.address()?;
        Ok(match &self.token {
            Some(t) => format!("http://{address}/?token={t}"),
            None => format!("http://{address}/"),
        })
    }

    /// Runs `stage` and serves it until `stop` is raised; says what the
    /// simulation did.
    pub fn serve(self, stage: Box<dyn Stage>, stop: Arc<AtomicBool>) -> Result<Summary, String> {
        let out = Outlets::new();
        let (commands, received) = std::sync::mpsc::channel();
        let runner = Runner::new(
            stage,
            received,
            out.clone(),
            stop.clone(),
            self.options.display_hz,
            self.options.speed,
        );
        let simulation = std::thread::Builder::new()
            .name("animats-simulation".into())
            .spawn(move || runner.run())
            .map_err(|e| format!("cannot start the simulation thread: {e}"))?;

        let app = server::App {
            out,
            commands,
            clients: Arc::new(AtomicUsize::new(0)),
            max_clients: self.options.max_clients,
            token: self.token.as_deref().map(Arc::from),
        };
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .enable_all()
            .build()
            .map_err(|e| format!("cannot start the web server: {e}"))?;
        let served: Result<(), String> = runtime.block_on(async {
            let listener = tokio::net::TcpListener::from_std(self.listener)
                .map_err(|e| format!("cannot listen: {e}"))?;
            let stopped = {
                let stop = stop.clone();
                async move {
                    while !stop.load(Ordering::Relaxed) {
                        tokio::time::sleep(Duration::from_millis(50)).await;
                    }
                }
            };
            tokio::select! {
                r = axum::serve(listener, server::router(app)) => r.map_err(|e| format!("the web server failed: {e}")),
                () = stopped => Ok(()),
            }
        });
        // Open WebSockets are not waited for.
        runtime.shutdown_timeout(Duration::from_millis(200));
        stop.store(true, Ordering::Relaxed);
        let summary = simulation
            .join()
            .map_err(|_| "the simulation thread failed".to_string())?;
        served.map(|()| summary)
    }
}
