//! `animats evaluate SCENE [--json]`: the scene's `[evolve]` evaluation,
//! once, as `animats evolve SCENE` scores a candidate.

use crate::Failure;
use animats_scene::evaluate::evaluate;
use std::path::PathBuf;

/// Arguments of `animats evaluate`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene file with an `[evolve]` table.
    scene: PathBuf,
    /// Print one JSON object (`fitness`, `distance`, `time`, `ended`).
    #[arg(long)]
    json: bool,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let scene = animats_scene::load(&args.scene).map_err(|e| Failure::Input(e.to_string()))?;
    crate::warn(&args.scene, &scene.warnings);
    if scene.evolve.is_none() {
        return Err(Failure::Input(format!(
            "{}: the scene has no [evolve] table: nothing to evaluate (docs/SCENES.md)",
            args.scene.display()
        )));
    }
    let e = evaluate(scene).map_err(Failure::Other)?;
    if args.json {
        let out = serde_json::json!({
            "fitness": e.fitness,
            "distance": e.distance,
            "time": e.time,
            "ended": e.ended.to_string(),
        });
        println!("{out}");
    } else {
        println!("fitness   {}", e.fitness);
        println!("distance  {} m", e.distance);
        println!("time      {} s", e.time);
        println!("ended     {}", e.ended);
    }
    Ok(())
}
