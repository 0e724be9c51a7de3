//! `animats hop [PARAMS]`: the thesis's roobot (the built-in
//! `scenes/hop_evolver.toml`) evaluated once with a hopping parameter set,
//! or any scene of one roobot (a `best.toml` that `animats evolve` wrote),
//! reported with its hops, stances and foot contacts.

use crate::output::Trajectory;
use crate::Failure;
use animats_creatures::roobot::gait::GaitLog;
use animats_creatures::roobot::params_file;
use animats_scene::evaluate::{evaluate_with, SceneProblem};
use animats_scene::Scene;
use std::path::Path;

/// Arguments of `animats hop`.
#[derive(clap::Args)]
pub struct Args {
    /// A parameter file, a built-in set (`evolved`: our best; `initial`:
    /// Appendix B's starting point), or a scene of one roobot with an
    /// `[evolve]` table (a `best.toml` of `animats evolve`).
    #[arg(default_value = "evolved")]
    params: String,
    /// Take lane K's set from a parameter file's `[[lane_best]]` tables.
    #[arg(long)]
    lane: Option<usize>,
    /// Longest evaluation, s.
    #[arg(long, default_value_t = 20.0, value_parser = crate::eval_seconds)]
    seconds: f64,
    /// Write the trajectory (`.csv` or `.jsonl`, as `animats simulate` does).
    #[arg(long, short)]
    output: Option<std::path::PathBuf>,
    /// Record every N-th step.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    every: u64,
}

/// Whether `path` names a scene file (one with an `[evolve]` table) rather
/// than a parameter file.
fn is_scene(path: &str) -> bool {
    !params_file::BUILT_IN.contains(&path)
        && animats_files::read_text(Path::new(path), animats_scene::MAX_FILE_BYTES)
            .ok()
            .and_then(|t| t.parse::<toml::Table>().ok())
            .is_some_and(|t| t.contains_key("evolve"))
}

/// The scene to run: the thesis's with `args.params`, or the scene given.
fn scene(args: &Args) -> Result<Scene, Failure> {
    let input = |e: String| Failure::Input(e);
    let problem = if is_scene(&args.params) {
        if args.lane.is_some() {
            return Err(input(format!(
                "{}: --lane takes a lane from a parameter file; a scene holds one brain",
                args.params
            )));
        }
        SceneProblem::load(Path::new(&args.params)).map_err(|e| input(e.to_string()))?
    } else {
        let params = animats_scene::params::load(&args.params, args.lane)
            .map_err(|e| input(e.to_string()))?;
        let thesis =
            SceneProblem::parse(animats_scene::HOP_EVOLVER, animats_scene::HOP_EVOLVER_FILE)
                .map_err(|e| Failure::Other(e.to_string()))?;
        return with_seconds(
            thesis.scene(&params.0).map_err(Failure::Other)?,
            args.seconds,
        );
    };
    with_seconds(problem.fresh().map_err(Failure::Other)?, args.seconds)
}

/// `scene` with its evaluation `seconds` long.
fn with_seconds(mut scene: Scene, seconds: f64) -> Result<Scene, Failure> {
    if let Some(spec) = scene.evolve.as_mut() {
        spec.duration = seconds;
    }
    Ok(scene)
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let scene = scene(&args)?;
    let spec = scene.evolve.clone().ok_or_else(|| {
        Failure::Input(format!("{}: the scene has no [evolve] table", args.params))
    })?;
    // The roobot whose brain is evolved: its controller has its name.
    let roobot = || {
        let controller = spec.index()?;
        (spec.table()?.0 == "roobot").then_some(())?;
        let foot = scene.particle(&format!("{}.foot", spec.controller.as_deref()?))?;
        Some((controller, foot))
    };
    let (controller, foot) = roobot().ok_or_else(|| {
        Failure::Input(format!(
            "{}: not a roobot's scene (its [evolve] controller is not a roobot's)",
            args.params
        ))
    })?;
    let mut trajectory = match &args.output {
        Some(path) => Some(Trajectory::create(path, &scene.names).map_err(Failure::Input)?),
        None => None,
    };
    let mut step = 0u64;
    let mut write_error = None;
    let mut gait = GaitLog::default();
    let (mut hops, mut last_state) = (0u32, None::<String>);
    let e = evaluate_with(scene, |s| {
        let state = s.nervous.controllers[controller]
            .brain
            .state()
            .map(str::to_string);
        if last_state.as_deref() == Some("flight") && state.as_deref() == Some("stance") {
            hops += 1;
        }
        gait.observe(&s.world, foot, state.as_deref() == Some("stance"));
        last_state = state;
        if let Some(t) = trajectory.as_mut() {
            if step.is_multiple_of(args.every) {
                if let Err(e) = t.record(s.world.time(), step, s.world.state()) {
                    write_error.get_or_insert(e);
                }
            }
        }
        step += 1;
    })
    .map_err(Failure::Other)?;
    if let Some(e) = write_error {
        return Err(Failure::Other(e));
    }
    say!(
        "parameters: {}{}",
        args.params,
        args.lane.map_or(String::new(), |l| format!(" (lane {l})"))
    );
    say!(
        "fitness:    {:.4}  (time upright + 50 × distance)",
        e.fitness
    );
    say!("upright:    {:.3} s", e.time);
    say!("distance:   {:.4} m", e.distance);
    say!("hops:       {hops} (landings the brain counted: its FSM going from flight to stance)");
    let speed = if e.time > 0.0 {
        e.distance / e.time
    } else {
        0.0
    };
    say!("speed:      {speed:.4} m/s (mean forward)");
    say!("ended:      {}", e.ended);
    match gait.stance_summary() {
        Some((lo, mid, hi)) => say!(
            "stances:    {} (FSM stance, s: min {lo:.3}, median {mid:.3}, max {hi:.3})",
            gait.stances.len()
        ),
        None => say!("stances:    0"),
    }
    if let (Some((lo, mid, hi)), Some((_, slide_mid, slide_max))) =
        (gait.contact_summary(), gait.slide_summary())
    {
        say!(
            "contacts:   {} (times the foot came down on the floor, as the physics saw it; fewer than hops when the brain's flight ends without the foot leaving the floor. On the floor, s: min {lo:.3}, median {mid:.3}, max {hi:.3}; slide median {:.1} mm, max {:.1} mm)",
            gait.contacts.len(),
            slide_mid * 1e3,
            slide_max * 1e3
        );
    }
    if let Some(t) = trajectory {
        let frames = t.frames();
        let path = t.finish().map_err(Failure::Other)?;
        say!("wrote {frames} recorded steps to {}", path.display());
    }
    Ok(())
}
