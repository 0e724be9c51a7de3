//! `animats simulate SCENE`: run a scene file headless.

use crate::output::Trajectory;
use crate::{positive_f64, Failure};
use animats_engine::{IntegratorKind, SimError};
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
}

fn parse_integrator(s: &str) -> Result<IntegratorKind, String> {
    s.parse()
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let mut scene = animats_scene::load(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    let dt = args.dt.unwrap_or(scene.dt);
    let duration = args.duration.unwrap_or(scene.duration);
    if let Some(kind) = args.integrator {
        scene.world.set_integrator(kind);
    }
    let steps = (duration / dt).round();
    if steps < 1.0 {
        return Err(Failure::Input(format!(
            "the duration ({duration} s) is shorter than half a step ({dt} s): nothing to simulate"
        )));
    }
    if steps > 1e12 {
        return Err(Failure::Input(format!(
            "{steps} steps is too many: raise --dt or lower --duration"
        )));
    }
    let steps = steps as u64;

    let mut trajectory = match &args.output {
        Some(path) => Some(Trajectory::create(path, &scene.names).map_err(Failure::Input)?),
        None => None,
    };
    let conservative = scene.world.is_conservative();
    let e0 = scene.world.energy().total();
    let write_err = |m: String| Failure::Other(m);

    let start = Instant::now();
    if let Some(t) = trajectory.as_mut() {
        t.record(scene.world.time(), 0, scene.world.state())
            .map_err(write_err)?;
    }
    for step in 1..=steps {
        if let Err(e) = scene.step(dt) {
            let message = match e {
                SimError::NonFinite { particle, time } => format!(
                    "{}: the simulation went non-finite at t = {time} s (step {step} of {steps}): particle `{}` has a non-finite position or velocity; try a smaller --dt",
                    args.scene.display(),
                    scene.name(particle)
                ),
                other => format!("{}: {other}", args.scene.display()),
            };
            let kept = trajectory.and_then(|t| t.abandon());
            let note = kept.map_or(String::new(), |p| {
                format!("\n(the trajectory up to then is in {})", p.display())
            });
            return Err(Failure::Blowup(format!("{message}{note}")));
        }
        if let Some(t) = trajectory.as_mut() {
            if step % args.every == 0 || step == steps {
                t.record(scene.world.time(), step, scene.world.state())
                    .map_err(write_err)?;
            }
        }
    }
    let wall = start.elapsed().as_secs_f64();

    let world = &scene.world;
    let stats = world.stats();
    println!(
        "{}: {} particles, {} springs, {} angle joints, {} torque joints",
        args.scene.display(),
        world.len(),
        world.forces().springs.len(),
        world.forces().angle_joints.len(),
        world.forces().torque_joints.len()
    );
    println!(
        "integrator {}, dt {dt} s, {steps} steps to t = {} s",
        world.integrator(),
        world.time()
    );
    println!("backtracks: {}", stats.backtracks);
    println!(
        "wall time: {wall:.4} s ({:.1} simulated s per wall s)",
        world.time() / wall.max(1e-9)
    );
    if conservative {
        let e1 = world.energy().total();
        let rel = if e0 != 0.0 {
            (e1 - e0) / e0.abs()
        } else {
            e1 - e0
        };
        println!("energy: E0 = {e0:.12e} J, E = {e1:.12e} J, drift {rel:+.3e} (relative)");
    } else {
        println!("energy: not reported (the scene has dissipative or driven forces or events)");
    }
    if let Some(t) = trajectory {
        let frames = t.frames();
        let path = t.finish().map_err(write_err)?;
        println!("wrote {frames} recorded steps to {}", path.display());
    }
    Ok(())
}
