//! `animats evaluate SCENE [--json]`: the scene's `[evolve]` evaluation,
//! once, as `animats evolve SCENE` scores a candidate. `animats evaluate
//! roobot [--params P] [--lane K]`: the roobot's, as `animats evolve` (and
//! Python's `animats.evaluate("roobot", …)`) scores its parameters.

use crate::Failure;
use animats_creatures::roobot::evaluate::{evaluate as evaluate_roobot, EvalSettings};
use animats_creatures::roobot::params_file;
use animats_scene::evaluate::evaluate;
use std::path::PathBuf;

/// Arguments of `animats evaluate`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene file with an `[evolve]` table, or `roobot` (when no file of
    /// that name exists) for the roobot's hopping gait.
    scene: PathBuf,
    /// The roobot's parameters: `initial`, `evolved` or a file (roobot only).
    #[arg(long, default_value = "evolved")]
    params: String,
    /// Which lane's best to take from a best.toml (roobot only).
    #[arg(long)]
    lane: Option<usize>,
    /// Print one JSON object (`fitness`, `distance`, `time`, `ended`).
    #[arg(long)]
    json: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let (fitness, distance, time, ended) = if args.scene.as_os_str() == "roobot"
        && !args.scene.exists()
    {
        let params = params_file::load(&args.params, args.lane)
            .map_err(|e| Failure::Input(e.to_string()))?;
        let e = evaluate_roobot(params, &EvalSettings::default())
            .map_err(|e| Failure::Other(e.to_string()))?;
        (
            e.fitness,
            e.distance,
            e.time_up,
            e.ending.name().to_string(),
        )
    } else {
        if args.lane.is_some() || args.params != "evolved" {
            return Err(Failure::Input(
                "--params and --lane are the roobot's: a scene's parameters are in its file".into(),
            ));
        }
        let scene = animats_scene::load(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
        crate::warn(&args.scene, &scene.warnings);
        if scene.evolve.is_none() {
            return Err(Failure::Input(format!(
                "{}: the scene has no [evolve] table: nothing to evaluate (docs/SCENES.md)",
                args.scene.display()
            )));
        }
        let e = evaluate(scene).map_err(Failure::Other)?;
        (e.fitness, e.distance, e.time, e.ended.to_string())
    };
    if args.json {
        let out = serde_json::json!({
            "fitness": fitness,
            "distance": distance,
            "time": time,
            "ended": ended,
        });
        println!("{out}");
    } else {
        println!("fitness   {fitness}");
        println!("distance  {distance} m");
        println!("time      {time} s");
        println!("ended     {ended}");
    }
    Ok(())
}
