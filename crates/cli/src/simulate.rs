//! `animats simulate SCENE`: run a scene file headless.

use crate::output::Trajectory;
use crate::{positive_f64, Failure};
use animats_engine::{IntegratorKind, Shown, SimError};
use animats_scene::Scene;
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `animats simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// The scene file (TOML).
    scene: PathBuf,
    /// Simulated seconds (overrides the scene's `[world] duration`).
    #[arg(long, value_parser = positive_f64)]
    duration: Option<f64>,
    /// Step in seconds (overrides `[world] dt`).
    #[arg(long, value_parser = positive_f64)]
    dt: Option<f64>,
    /// Integration method (overrides `[world] integrator`).
    #[arg(long, value_parser = parse_integrator)]
    integrator: Option<IntegratorKind>,
    /// Write the trajectory here: `.csv` or `.jsonl`.
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// Record every N-th step (t = 0 and the last step are always recorded).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    every: u64,
    /// Pace the simulation to the wall clock, adapting the step each second
    /// as the thesis's SeaWorld does (never above the scene's `max_dt`).
    #[arg(long)]
    realtime: bool,
    /// Frames per second to aim for with --realtime.
    #[arg(long, default_value_t = 60.0, value_parser = positive_f64)]
    fps: f64,
}

/// The error for a blow-up at `step`: when, and which particle by name;
/// the trajectory so far is kept under a `.partial` name, never the
/// requested one.
fn blowup(
    args: &Args,
    scene: &animats_scene::Scene,
    e: &SimError,
    step: &str,
    trajectory: Option<Trajectory>,
) -> Failure {
    let message = match e.blame() {
        Some((particle, time)) => format!(
            "{}: the simulation {} at t = {time} s ({step}): {}; try a smaller --dt",
            args.scene.display(),
            if matches!(e, SimError::NonFinite { .. }) {
                "went non-finite"
            } else {
                "diverged"
            },
            e.what(scene.name(particle))
        ),
        None => format!("{}: {e}", args.scene.display()),
    };
    let kept = trajectory.and_then(|t| t.abandon());
    let note = kept.map_or(String::new(), |p| {
        format!("\n(the trajectory up to then is in {})", p.display())
    });
    Failure::Blowup(format!("{message}{note}"))
}

fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    s.parse()
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    if args.realtime {
        return realtime(args);
    }
    let (mut scene, dt, steps) = prepare(&args)?;
    let limit = scene.world.step_limit(scene.world.integrator());
    let mut trajectory = match &args.output {
        Some(path) => {
            // t = 0, every --every-th step and the last.
            let frames = 1 + steps / args.every + u64::from(!steps.is_multiple_of(args.every));
            crate::output::check_room(path, frames, &scene.names).map_err(Failure::Input)?;
            Some(Trajectory::create(path, &scene.names).map_err(Failure::Input)?)
        }
        None => None,
    };
    let conservative = scene.world.is_conservative();
    let e0 = scene.world.energy().total();
    let start = Instant::now();
    let iterations = run_steps(&args, &mut scene, dt, steps, &mut trajectory)?;
    let wall = start.elapsed().as_secs_f64();
    report(&args, &scene, dt, steps, limit, iterations, wall);
    if conservative {
        let e1 = scene.world.energy().total();
        let rel = if e0 != 0.0 {
            (e1 - e0) / e0.abs()
        } else {
            e1 - e0
        };
        say!("energy: E0 = {e0:.12e} J, E = {e1:.12e} J, drift {rel:+.3e} (relative)");
    } else {
        say!("energy: not reported (the scene has dissipative or driven forces or events)");
    }
    if let Some(t) = trajectory {
        let frames = t.frames();
        let path = t.finish().map_err(Failure::Other)?;
        say!("wrote {frames} recorded steps to {}", path.display());
    }
    Ok(())
}

/// The scene with the command line's integrator, its step and its number
/// of steps, checked.
fn prepare(args: &Args) -> Result<(Scene, f64, u64), Failure> {
    let mut scene = animats_scene::load(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    crate::warn(&args.scene, &scene.warnings);
    let dt = args.dt.unwrap_or(scene.dt);
    let duration = args.duration.unwrap_or(scene.duration);
    if let Some(kind) = args.integrator {
        scene.world.set_integrator(kind);
    }
    // The scene's own step was checked when it loaded; a step or an
    // integrator from the command line is checked here.
    if args.dt.is_some() || args.integrator.is_some() {
        let warning = animats_scene::build::step_warning(&scene.world, &scene.names, dt);
        crate::warn(&args.scene, warning.as_slice());
    }
    // Where each came from, for the messages below.
    let file = args.scene.display();
    let of_duration = if args.duration.is_some() {
        "--duration"
    } else {
        "[world] duration"
    };
    let of_dt = if args.dt.is_some() {
        "--dt"
    } else {
        "[world] dt"
    };
    let (d, h) = (Shown(duration), Shown(dt));
    let steps = (duration / dt).round();
    if steps < 1.0 {
        return Err(Failure::Input(format!(
            "{file}: the duration ({d} s, {of_duration}) is shorter than half a step ({h} s, {of_dt}): nothing to simulate"
        )));
    }
    if steps > 1e12 {
        let count = if steps.is_finite() {
            format!("{steps:.1e} steps")
        } else {
            "over 1e308 steps".to_string()
        };
        return Err(Failure::Input(format!(
            "{file}: {count} ({d} s of {of_duration} at {h} s of {of_dt}) is too many (at most 1e12): raise the step or shorten the run"
        )));
    }
    Ok((scene, dt, steps as u64))
}

/// Takes `steps` steps of `dt`, recording every `--every`-th; returns the
/// implicit integrator's conjugate-gradient iterations in all.
fn run_steps(
    args: &Args,
    scene: &mut Scene,
    dt: f64,
    steps: u64,
    trajectory: &mut Option<Trajectory>,
) -> Result<u64, Failure> {
    if let Some(t) = trajectory.as_mut() {
        t.record_scene(scene, 0).map_err(Failure::Other)?;
    }
    // A world that splits its work over threads enters the pool once for
    // the whole run instead of at every step (the same bits).
    let pooled = scene.world.steps_on_pool();
    let run = || -> Result<u64, Failure> {
        let mut iterations = 0u64;
        for step in 1..=steps {
            let stepped = scene.step(dt);
            iterations += scene.world.last_step().solver_iterations as u64;
            if let Err(e) = stepped {
                let step = format!("step {step} of {steps}");
                return Err(blowup(args, scene, &e, &step, trajectory.take()));
            }
            if let Some(t) = trajectory.as_mut() {
                if step % args.every == 0 || step == steps {
                    t.record_scene(scene, step).map_err(Failure::Other)?;
                }
            }
        }
        Ok(iterations)
    };
    animats_engine::on_pool_if(pooled, run)
}

/// Prints the run's summary (but for its energy).
fn report(
    args: &Args,
    scene: &Scene,
    dt: f64,
    steps: u64,
    limit: Option<animats_engine::StepLimit>,
    iterations: u64,
    wall: f64,
) {
    let world = &scene.world;
    say!(
        "{}: {} particles, {} springs, {} angle joints, {} torque joints",
        args.scene.display(),
        world.len(),
        world.forces().springs.len(),
        world.forces().angle_joints.len(),
        world.forces().torque_joints.len()
    );
    say!(
        "integrator {}, dt {dt} s, {steps} steps to t = {} s",
        world.integrator(),
        world.time()
    );
    match limit {
        Some(l) => {
            say!(
            "recommended step for {}: {:.3e} s (spring modes up to {:.1} rad/s, at particle `{}`)",
            world.integrator(),
            l.dt,
            l.omega,
            scene.names.get(l.particle.index()).map_or("?", String::as_str)
        )
        }
        None if world.integrator().is_explicit() => {
            say!("recommended step: no spring limits it")
        }
        None => {
            let explicit = world.recommended_dt(IntegratorKind::Symplectic);
            say!(
                "recommended step for implicit: any (stable at every step{})",
                explicit.map_or(String::new(), |h| format!(
                    "; symplectic Euler would need below {h:.3e} s"
                ))
            );
            say!(
                "linear solves: {:.1} conjugate-gradient iterations a step (tolerance {:e})",
                iterations as f64 / steps as f64,
                world.solver().tolerance
            );
        }
    }
    say!("backtracks: {}", world.stats().backtracks);
    if let Some(c) = world.event::<animats_engine::SphereContact>() {
        let asleep = if c.def().sleep_speed > 0.0 {
            format!(", {} spheres asleep", c.sleeping())
        } else {
            String::new()
        };
        say!(
            "sphere contacts at the end: {} pairs touching{asleep}",
            c.touching()
        );
    }
    say!(
        "wall time: {wall:.4} s ({:.1} simulated s per wall s)",
        world.time() / wall.max(1e-9)
    );
}

/// The thesis's SeaWorld loop (§5.3, Appendix B): frames at a steady rate;
/// once a second the simulated time per frame is moved a quarter of the way
/// towards the real time per frame, `new = (3 old + interval/frames)/4`, so
/// the simulation tracks the wall clock. A frame is taken in equal steps no
/// longer than the scene's `max_dt` (the thesis took one step per frame and
/// capped it, falling behind real time when the cap bit).
fn realtime(args: Args) -> Result<(), Failure> {
    use std::time::Duration;
    let mut scene = animats_scene::load(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    crate::warn(&args.scene, &scene.warnings);
    if let Some(kind) = args.integrator {
        scene.world.set_integrator(kind);
    }
    let max_dt = args.dt.map_or(scene.max_dt, |d| d.min(scene.max_dt));
    let duration = args.duration.unwrap_or(scene.duration);
    let mut trajectory = match &args.output {
        Some(path) => Some(Trajectory::create(path, &scene.names).map_err(Failure::Input)?),
        None => None,
    };
    if let Some(t) = trajectory.as_mut() {
        t.record(0.0, 0, scene.world.state())
            .map_err(Failure::Other)?;
    }
    let frame_period = Duration::from_secs_f64(1.0 / args.fps);
    let mut frame_dt = 1.0 / args.fps;
    let start = Instant::now();
    let mut next_frame = start;
    let (mut second_start, mut frames, mut sim_at_second) = (start, 0u64, 0.0);
    let mut steps = 0u64;
    let mut busy = Duration::ZERO;
    say!(
        "{}: real time at {} frames/s, steps of at most {max_dt} s; Ctrl-C to stop",
        args.scene.display(),
        args.fps
    );
    // As in `run`: a world that splits its work enters the pool once.
    let pooled = scene.world.steps_on_pool();
    let run = || -> Result<(), Failure> {
        while scene.world.time() < duration - 1e-12 {
            let work = Instant::now();
            let frame = frame_dt.min(duration - scene.world.time());
            let n = (frame / max_dt).ceil().max(1.0);
            let h = frame / n;
            for _ in 0..n as u64 {
                if let Err(e) = scene.step(h) {
                    let step = format!("step {}", steps + 1);
                    return Err(blowup(&args, &scene, &e, &step, trajectory.take()));
                }
                steps += 1;
                if let Some(t) = trajectory.as_mut() {
                    if steps.is_multiple_of(args.every) {
                        t.record(scene.world.time(), steps, scene.world.state())
                            .map_err(Failure::Other)?;
                    }
                }
            }
            busy += work.elapsed();
            frames += 1;
            next_frame += frame_period;
            let now = Instant::now();
            if next_frame > now {
                std::thread::sleep(next_frame - now);
            } else {
                next_frame = now; // behind: do not try to catch up in a burst
            }
            let interval = second_start.elapsed().as_secs_f64();
            if interval >= 1.0 {
                let sim = scene.world.time() - sim_at_second;
                say!(
                    "t = {:7.2} s  {:5.1} frames/s  simulated/real {:.3}  step {:.5} s  CPU {:.1}%",
                    scene.world.time(),
                    frames as f64 / interval,
                    sim / interval,
                    frame_dt / n,
                    100.0 * busy.as_secs_f64() / interval
                );
                frame_dt = (3.0 * frame_dt + interval / frames as f64) / 4.0;
                (second_start, frames, sim_at_second, busy) =
                    (Instant::now(), 0, scene.world.time(), Duration::ZERO);
            }
        }
        Ok(())
    };
    animats_engine::on_pool_if(pooled, run)?;
    if let Some(t) = trajectory {
        let written = t.frames();
        let path = t.finish().map_err(Failure::Other)?;
        say!("wrote {written} recorded steps to {}", path.display());
    }
    say!(
        "{steps} steps to t = {:.3} s in {:.2} s of wall time",
        scene.world.time(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
