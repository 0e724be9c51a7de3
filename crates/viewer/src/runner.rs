//! The simulation thread: owns the [`Stage`], obeys the clients' commands,
//! paces simulated time to the wall clock (or runs flat out), and publishes
//! a frame at the display rate.
//!
//! Frames go out through a `watch` channel, which keeps only the newest: a
//! slow client skips frames instead of slowing the simulation, and with no
//! client attached nothing is even serialised.

use crate::protocol::{Command, Frame};
use crate::stage::Stage;
use axum::extract::ws::Utf8Bytes;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tokio::sync::watch;

/// Slowest and fastest real-time factors a client may ask for.
pub const SPEED_RANGE: (f64, f64) = (0.01, 100.0);
/// When the simulation falls behind the wall clock by more than this many
/// wall seconds, the debt is forgiven rather than caught up in a burst.
const MAX_LAG: f64 = 0.25;

/// The channels a runner publishes to.
#[derive(Clone)]
pub struct Outlets {
    /// The scene description, JSON (re-sent after a reset).
    pub scene: Arc<watch::Sender<Utf8Bytes>>,
    /// The newest frame, JSON.
    pub frames: Arc<watch::Sender<Utf8Bytes>>,
}

impl Outlets {
    /// Empty channels.
    pub fn new() -> Outlets {
        Outlets {
            scene: Arc::new(watch::channel(Utf8Bytes::from_static("")).0),
            frames: Arc::new(watch::channel(Utf8Bytes::from_static("")).0),
        }
    }
}

impl Default for Outlets {
    fn default() -> Self {
        Outlets::new()
    }
}

/// Runs a stage live.
pub struct Runner {
    stage: Box<dyn Stage>,
    commands: Receiver<Command>,
    out: Outlets,
    stop: Arc<AtomicBool>,
    period: Duration,
    /// Real-time factor; 0 is flat out.
    speed: f64,
    paused: bool,
    /// True until the first tab connects: nothing is simulated unseen.
    waiting: bool,
    error: Option<String>,
    positions: Vec<f32>,
    /// What is drawn (from the last scene published): its bells are shaped
    /// here for every frame.
    drawing: animats_view::Drawing,
    summary: Summary,
}

/// What a run did, for the report when it stops.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Summary {
    /// Simulated seconds stepped (over resets).
    pub simulated: f64,
    /// Wall seconds the runner ran.
    pub wall: f64,
    /// Physics steps taken.
    pub steps: u64,
    /// Frames published to clients.
    pub frames: u64,
}

impl Summary {
    /// Simulated seconds per wall second.
    pub fn real_time_factor(&self) -> f64 {
        if self.wall > 0.0 {
            self.simulated / self.wall
        } else {
            0.0
        }
    }
}

impl Runner {
    /// A runner publishing `display_hz` frames a second at real-time
    /// factor `speed` (0: flat out).
    pub fn new(
        stage: Box<dyn Stage>,
        commands: Receiver<Command>,
        out: Outlets,
        stop: Arc<AtomicBool>,
        display_hz: f64,
        speed: f64,
    ) -> Runner {
        let mut runner = Runner {
            stage,
            commands,
            out,
            stop,
            period: Duration::from_secs_f64(1.0 / display_hz.clamp(1.0, 240.0)),
            speed: clamp_speed(speed),
            paused: false,
            waiting: true,
            error: None,
            positions: Vec::new(),
            drawing: Default::default(),
            summary: Summary::default(),
        };
        runner.publish_scene();
        runner
    }

    fn publish_scene(&mut self) {
        let describe = self.stage.describe();
        let json = serde_json::to_string(&describe).unwrap_or_default();
        self.drawing = describe.drawing;
        self.out.scene.send_replace(json.into());
    }

    /// Steps while `more` says so; a large world's loop runs on the thread
    /// pool, entering it once instead of at every step (the same bits).
    fn step_while(&mut self, more: impl Fn(&Runner) -> bool + Send) {
        let pooled = self.stage.steps_on_pool();
        animats_engine::on_pool_if(pooled, move || {
            while more(self) {
                self.step();
            }
        });
    }

    /// Steps once, recording a failure (which pauses the run).
    fn step(&mut self) {
        let dt = self.stage.dt();
        self.summary.steps += 1;
        self.summary.simulated += dt;
        if let Err(e) = self.stage.step(dt) {
            let message = format!(
                "the simulation failed at t = {:.3} s: {e}",
                self.stage.time()
            );
            eprintln!("viewer: {message} (paused; reset to start again)");
            self.error = Some(message);
            self.paused = true;
        }
    }

    fn obey(&mut self, command: Command) {
        match command {
            Command::Pause => self.paused = true,
            Command::Resume if self.error.is_none() => self.paused = false,
            Command::Resume => {}
            Command::Step if self.paused && self.error.is_none() => self.step(),
            Command::Step => {}
            Command::Speed { value } => self.speed = clamp_speed(value),
            Command::Reset => match self.stage.reset() {
                Ok(()) => {
                    self.error = None;
                    self.publish_scene();
                }
                Err(e) => eprintln!("viewer: cannot reset: {e}"),
            },
            Command::Food { x, z } => {
                if x.is_finite() && z.is_finite() {
                    self.stage.move_food(x, z);
                }
            }
        }
    }

    /// Runs until the stop flag is raised or every command sender is gone.
    pub fn run(mut self) -> Summary {
        let started = Instant::now();
        self.run_until_stopped();
        self.summary.wall = started.elapsed().as_secs_f64();
        self.summary
    }

    fn run_until_stopped(&mut self) {
        let mut next_frame = Instant::now();
        let mut last = Instant::now();
        // Simulated time the wall clock says we should have reached.
        let mut target = self.stage.time();
        let mut window = (Instant::now(), self.stage.time(), 0u32);
        let (mut fps, mut rtf) = (0.0, 0.0);
        loop {
            if self.stop.load(Ordering::Relaxed) {
                return;
            }
            loop {
                match self.commands.try_recv() {
                    Ok(c) => {
                        let reset = c == Command::Reset;
                        self.obey(c);
                        if reset {
                            target = self.stage.time();
                            window = (Instant::now(), self.stage.time(), 0);
                        }
                    }
                    Err(TryRecvError::Empty) => break,
                    Err(TryRecvError::Disconnected) => return,
                }
            }

            if self.waiting {
                if self.out.frames.receiver_count() == 0 {
                    std::thread::sleep(self.period);
                    last = Instant::now();
                    next_frame = last;
                    target = self.stage.time();
                    window = (last, self.stage.time(), 0);
                    continue;
                }
                self.waiting = false;
            }
            let now = Instant::now();
            let wall = now.duration_since(last).as_secs_f64();
            last = now;
            if self.paused {
                target = self.stage.time();
            } else if self.speed == 0.0 {
                self.step_while(move |r| Instant::now() < next_frame && !r.paused);
                target = self.stage.time();
            } else {
                target += self.speed * wall.min(MAX_LAG);
                let half = 0.5 * self.stage.dt();
                self.step_while(move |r| {
                    r.stage.time() + half < target && Instant::now() < next_frame && !r.paused
                });
                // Too slow for this speed: drop the debt, report the true rate.
                target = target.min(self.stage.time() + self.speed * MAX_LAG);
            }

            let now = Instant::now();
            if now < next_frame {
                std::thread::sleep(next_frame - now);
            }
            next_frame += self.period;
            let now = Instant::now();
            if next_frame < now {
                next_frame = now + self.period;
            }

            window.2 += 1;
            let span = now.duration_since(window.0).as_secs_f64();
            if span >= 1.0 {
                fps = f64::from(window.2) / span;
                rtf = (self.stage.time() - window.1) / span;
                window = (now, self.stage.time(), 0);
            }
            // Nobody watching: nothing to serialise.
            if self.out.frames.receiver_count() > 0 {
                self.publish_frame(fps, rtf);
                self.summary.frames += 1;
            }
        }
    }

    fn publish_frame(&mut self, fps: f64, rtf: f64) {
        self.stage.positions(&mut self.positions);
        let creatures = self.stage.creatures();
        let shaped = !(self.drawing.bells.is_empty() && self.drawing.axles.is_empty());
        let at: Vec<animats_engine::DVec3> = if shaped {
            self.positions
                .chunks_exact(3)
                .map(|c| [c[0], c[1], c[2]].map(f64::from).into())
                .collect()
        } else {
            Vec::new()
        };
        let bells = if self.drawing.bells.is_empty() {
            Vec::new()
        } else {
            self.drawing.bell_shapes(&at, &creatures)
        };
        let levels = self.stage.levels();
        let frame = Frame {
            kind: "frame",
            t: self.stage.time(),
            fps,
            rtf,
            speed: self.speed,
            paused: self.paused,
            p: std::mem::take(&mut self.positions),
            creatures,
            bells,
            rods: if self.drawing.rods.iter().any(|r| r.muscle.is_some()) {
                self.drawing.rod_colours(&levels)
            } else {
                Vec::new()
            },
            axles: self
                .drawing
                .axle_ends(&at)
                .into_iter()
                .map(|ends| ends.map(|e| e.map(|x| x as f32)))
                .collect(),
            axle_colours: if self.drawing.axles.iter().any(|x| x.motor.is_some()) {
                self.drawing.axle_colours(&levels)
            } else {
                Vec::new()
            },
            focus: self.stage.focus(),
            error: self.error.clone(),
            note: self.stage.note(),
        };
        let json = serde_json::to_string(&frame).unwrap_or_default();
        self.positions = frame.p;
        self.out.frames.send_replace(json.into());
    }
}

/// A requested real-time factor, made safe: not positive (or NaN) is flat
/// out, the rest is clamped to [`SPEED_RANGE`].
pub fn clamp_speed(value: f64) -> f64 {
    if value > 0.0 {
        value.clamp(SPEED_RANGE.0, SPEED_RANGE.1)
    } else {
        0.0
    }
}
