//! `animats hop [PARAMS]`: one roobot, one evaluation, reported.

use crate::output::Trajectory;
use crate::Failure;
use animats_creatures::roobot::evaluate::{evaluate_with, EvalSettings};
use animats_creatures::roobot::gait::GaitLog;

/// Arguments of `animats hop`.
#[derive(clap::Args)]
pub struct Args {
    /// A parameter file, or a built-in set: `evolved` (our best) or `initial`
    /// (Appendix B's starting point).
    #[arg(default_value = "evolved")]
    params: String,
    /// Take lane K's set from a `best.toml` written by `animats evolve`.
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

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let params = animats_scene::params::load(&args.params, args.lane)
        .map_err(|e| Failure::Input(e.to_string()))?;
    let settings = EvalSettings {
        seconds: args.seconds,
        ..EvalSettings::default()
    };
    let names: Vec<String> = ["hip", "foot", "head", "tail1", "tail2"]
        .iter()
        .map(|p| format!("roobot.{p}"))
        .collect();
    let mut trajectory = match &args.output {
        Some(path) => Some(Trajectory::create(path, &names).map_err(Failure::Input)?),
        None => None,
    };
    let mut step = 0u64;
    let mut write_error = None;
    let mut gait = GaitLog::default();
    let e = evaluate_with(params, &settings, |world, roobot| {
        gait.observe(world, roobot);
        if let Some(t) = trajectory.as_mut() {
            if step.is_multiple_of(args.every) {
                if let Err(e) = t.record(world.time(), step, world.state()) {
                    write_error.get_or_insert(e);
                }
            }
        }
        step += 1;
    })
    .map_err(|e| Failure::Other(e.to_string()))?;
    if let Some(e) = write_error {
        return Err(Failure::Other(e));
    }
    println!(
        "parameters: {}{}",
        args.params,
        args.lane.map_or(String::new(), |l| format!(" (lane {l})"))
    );
    println!(
        "fitness:    {:.4}  (time upright + 50 × distance)",
        e.fitness
    );
    println!("upright:    {:.3} s", e.time_up);
    println!("distance:   {:.4} m", e.distance);
    println!("hops:       {}", e.hops);
    println!("speed:      {:.4} m/s (mean forward)", e.mean_speed());
    println!("ended:      {}", e.ending);
    match gait.stance_summary() {
        Some((lo, mid, hi)) => println!(
            "stances:    {} (FSM stance, s: min {lo:.3}, median {mid:.3}, max {hi:.3})",
            gait.stances.len()
        ),
        None => println!("stances:    0"),
    }
    if let (Some((lo, mid, hi)), Some((_, slide_mid, slide_max))) =
        (gait.contact_summary(), gait.slide_summary())
    {
        println!(
            "contacts:   {} (foot on the floor, s: min {lo:.3}, median {mid:.3}, max {hi:.3}; slide median {:.1} mm, max {:.1} mm)",
            gait.contacts.len(),
            slide_mid * 1e3,
            slide_max * 1e3
        );
    }
    if let Some(t) = trajectory {
        let frames = t.frames();
        let path = t.finish().map_err(Failure::Other)?;
        println!("wrote {frames} recorded steps to {}", path.display());
    }
    Ok(())
}
