//! `animats evaluate SCENE [--json]`: the scene's `[evolve]` evaluation,
//! once, as `animats evolve SCENE` scores a candidate. `animats evaluate
//! roobot [--params P] [--lane K]`: the thesis's scene
//! (`scenes/hop_evolver.toml`, built in) with those hopping parameters, as
//! `animats evolve` (and Python's `animats.evaluate("roobot", …)`) scores
//! them.

use crate::Failure;
use animats_scene::evaluate::{evaluate, score, score_all, SceneProblem};
use std::path::PathBuf;

/// Arguments of `animats evaluate`.
#[derive(clap::Args)]
pub struct Args {
    /// A scene file with an `[evolve]` table, or `roobot` (when no file of
    /// that name exists): the thesis's scene, scenes/hop_evolver.toml, built
    /// in.
    scene: PathBuf,
    /// `roobot` only: its hopping parameters, `initial`, `evolved` or a file.
    #[arg(long, default_value = "evolved")]
    params: String,
    /// `roobot` only: which lane's set to take from a parameter file.
    #[arg(long)]
    lane: Option<usize>,
    /// Print one JSON object (`fitness`, `distance`, `time`, `ended`, and
    /// `measures` for a scene with an `[archive]`).
    #[arg(long)]
    json: bool,
    /// Where the scene is evaluated: cpu (the engine), cuda (an NVIDIA
    /// GPU: the same bits; docs/GPU.md says what it covers) or cuda-fast
    /// (the GPU with fused multiply-adds: not the same bits).
    #[arg(long, value_enum, default_value_t)]
    device: crate::device::DeviceName,
}

/// Runs the command.
pub fn run(args: Args) -> Result<(), Failure> {
    let input = |e: String| Failure::Input(e);
    let scene = if args.scene.as_os_str() == "roobot" && !args.scene.exists() {
        let params = animats_scene::params::load(&args.params, args.lane)
            .map_err(|e| input(e.to_string()))?;
        let thesis =
            SceneProblem::parse(animats_scene::HOP_EVOLVER, animats_scene::HOP_EVOLVER_FILE)
                .map_err(|e| Failure::Other(e.to_string()))?;
        let scene = thesis.scene(&params.0).map_err(Failure::Other)?;
        if let Some(b) = batches(&args, animats_scene::HOP_EVOLVER_FILE, || {
            thesis.scene(&params.0)
        })? {
            let mut e = (b.0)(vec![scene]).map_err(Failure::Other)?;
            return report(
                e.pop().ok_or(Failure::Other("no evaluation".into()))?,
                args.json,
            );
        }
        scene
    } else {
        if args.lane.is_some() || args.params != "evolved" {
            return Err(input(
                "--params and --lane are the roobot's: a scene's parameters are in its file".into(),
            ));
        }
        let file = args.scene.display().to_string();
        let text = animats_scene::read(&args.scene).map_err(|e| input(e.to_string()))?;
        let scene = animats_scene::parse(&text, &file).map_err(|e| input(e.to_string()))?;
        crate::warn(&args.scene, &scene.warnings);
        match &scene.evolve {
            None => {
                return Err(input(format!(
                    "{file}: the scene has no [evolve] table: nothing to evaluate (docs/SCENES.md)"
                )))
            }
            // Robust, trials: as evolution scores it.
            Some(_) => {
                let build = || animats_scene::parse(&text, &file).map_err(|e| e.to_string());
                let e = match batches(&args, &file, build)? {
                    None => score(build),
                    Some(b) => score_all(&[&build], &|_, _| true, &*b.0)
                        .and_then(|mut all| all.pop().ok_or_else(|| "no evaluation".to_string())),
                };
                return report(e.map_err(Failure::Other)?, args.json);
            }
        }
    };
    report(evaluate(scene).map_err(Failure::Other)?, args.json)
}

/// `--device`'s batches for `file`'s scene (none on the CPU); exit 2 where
/// the GPU cannot evaluate it or cannot be used.
fn batches(
    args: &Args,
    file: &str,
    probe: impl FnOnce() -> Result<animats_scene::Scene, String>,
) -> Result<Option<animats_scene::evaluate::Batches>, Failure> {
    crate::device::batches(args.device, file, probe).map_err(Failure::Input)
}

/// Prints an evaluation: a JSON object, or a line a field.
fn report(e: animats_scene::evaluate::Evaluation, json: bool) -> Result<(), Failure> {
    let (fitness, distance, time, ended) = (e.fitness, e.distance, e.time, e.ended.to_string());
    if json {
        let mut out = serde_json::json!({
            "fitness": fitness,
            "distance": distance,
            "time": time,
            "ended": ended,
        });
        // A scene with an [archive] adds its measures, in order; one whose
        // fitness counts energy, a target or terms adds them.
        if !e.measures.is_empty() {
            out["measures"] = serde_json::json!(e.measures);
        }
        if let Some(j) = e.energy {
            out["energy"] = serde_json::json!(j);
        }
        if let Some(d) = e.target_distance {
            out["target_distance"] = serde_json::json!(d);
        }
        if !e.terms.is_empty() {
            out["terms"] = serde_json::json!(e.terms);
        }
        say!("{out}");
    } else {
        say!("fitness   {fitness}");
        say!("distance  {distance} m");
        say!("time      {time} s");
        say!("ended     {ended}");
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        if !e.measures.is_empty() {
            say!("measures  {}", list(&e.measures));
        }
        if let Some(j) = e.energy {
            say!("energy    {j} J");
        }
        if let Some(d) = e.target_distance {
            say!("target    {d} m");
        }
        if !e.terms.is_empty() {
            say!("terms     {}", list(&e.terms));
        }
    }
    Ok(())
}
