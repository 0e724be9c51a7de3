//! `--device cpu|cuda|cuda-fast`: where `evaluate` and `evolve` run a
//! scene's evaluations. `cpu` (the default) is the engine on every core;
//! `cuda` hands them to an NVIDIA GPU a batch at a time (a generation's
//! runs at the scene's step, then those at half of it), one GPU thread per
//! run, with the same bits (docs/GPU.md); `cuda-fast` likewise with fused
//! multiply-adds allowed: not the CPU's bits.

use animats_creatures::random::Random;
use animats_evolve::run::ProblemSpec;
use animats_scene::evaluate::Batches;
use animats_scene::morphology::MorphologyProblem;
use animats_scene::Scene;

/// `--device`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum DeviceName {
    /// The engine, on every core.
    #[default]
    Cpu,
    /// An NVIDIA GPU (its driver and NVRTC are loaded at run time).
    Cuda,
    /// An NVIDIA GPU, fused multiply-adds allowed (`--fmad=true`): results
    /// drift from the engine's bits as a step's own errors do.
    CudaFast,
}

/// Where the evaluations of `file`'s scene run: `None` on the CPU; on
/// `cuda`, the GPU, once `probe()` (a scene as the run builds them) is
/// found to be one the GPU evaluates and a GPU is found. `Err` names the
/// file and the entry the GPU does not cover, or what is missing (driver,
/// device, NVRTC).
pub fn batches(
    device: DeviceName,
    file: &str,
    probe: impl FnOnce() -> Result<Scene, String>,
) -> Result<Option<Batches>, String> {
    match device {
        DeviceName::Cpu => Ok(None),
        DeviceName::Cuda | DeviceName::CudaFast => {
            let (flag, mode) = if device == DeviceName::Cuda {
                ("cuda", animats_gpu::Mode::Strict)
            } else {
                ("cuda-fast", animats_gpu::Mode::Fast)
            };
            let scene = probe()?;
            animats_gpu::Batch::pack_scenes(&[&scene]).map_err(|e| {
                format!(
                    "{file}: --device {flag}: {}",
                    e.strip_prefix("scene 0: ").unwrap_or(&e)
                )
            })?;
            let device =
                animats_gpu::Device::open_in(mode).map_err(|e| format!("--device {flag}: {e}"))?;
            // Which layout the first batches measured faster, on stderr.
            Ok(Some(device.into_batches_with(|line| eprintln!("{line}"))))
        }
    }
}

/// Evaluations a batch below which the GPU is no faster than a host's
/// cores: on the H200 beside 16 Xeon cores (docs/GPU.md), 4,096 roobots or
/// jellyfish a batch ran 1.8× the cores and 2,048 rough walkers 0.1×;
/// 8,192 and more, 2.8–6.2×.
pub const SMALL_BATCH: usize = 4096;

/// `batches` that say, on stderr, when the run's first batch is smaller
/// than [`SMALL_BATCH`] (one GPU thread runs one evaluation, far slower
/// than a CPU core: a GPU pays only with thousands at once). Later
/// batches are not judged: a generation's runs at half the step are few
/// by design.
pub fn note_small_batches(batches: Batches) -> Batches {
    note_small_batches_with(batches, |note| eprintln!("{note}"))
}

/// [`note_small_batches`], the note given to `say`.
fn note_small_batches_with(
    batches: Batches,
    say: impl Fn(String) + Send + Sync + 'static,
) -> Batches {
    let first = std::sync::atomic::AtomicBool::new(true);
    Batches(std::sync::Arc::new(move |scenes: Vec<Scene>| {
        let n = scenes.len();
        if first.swap(false, std::sync::atomic::Ordering::Relaxed) && n < SMALL_BATCH {
            say(format!(
                "note: a batch of {n} evaluations leaves most of the GPU idle (one thread each); the GPU pays from about {SMALL_BATCH} a batch: raise --population (docs/GPU.md)"
            ));
        }
        (batches.0)(scenes)
    }))
}

/// A scene of the problem as evolution builds them: the scene's own
/// brain, or a `[morphology]` scene's start body (a random one if it
/// starts from random bodies).
pub fn probe(spec: &ProblemSpec) -> Result<Scene, String> {
    if !spec.has_morphology()? {
        return spec.parse()?.fresh();
    }
    let m = MorphologyProblem::parse(&spec.text, &spec.file).map_err(|e| e.to_string())?;
    let genes = match m.start() {
        Some(g) => g.to_vec(),
        None => m.random(&mut Random::for_entry(0, 0)),
    };
    let text = m.develop(&genes, "")?;
    animats_scene::parse(&text, &spec.file).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, Mutex};

    const SCENE: &str = include_str!("../../../scenes/bouncing_ball.toml");

    /// What the batches were given (their sizes) and the notes said.
    type Log<T> = Arc<Mutex<Vec<T>>>;

    /// Batches that count the scenes they are given, and the notes said.
    fn counting() -> (Batches, Log<usize>, Log<String>) {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let notes = Arc::new(Mutex::new(Vec::new()));
        let s = seen.clone();
        let inner = Batches(Arc::new(move |scenes: Vec<Scene>| {
            s.lock().unwrap().push(scenes.len());
            Ok(Vec::new())
        }));
        let n = notes.clone();
        let b = note_small_batches_with(inner, move |note| n.lock().unwrap().push(note));
        (b, seen, notes)
    }

    fn scenes(n: usize) -> Vec<Scene> {
        (0..n)
            .map(|_| animats_scene::parse(SCENE, "scenes/bouncing_ball.toml").unwrap())
            .collect()
    }

    #[test]
    fn a_small_first_batch_is_noted_once_and_every_batch_still_runs() {
        let (b, seen, notes) = counting();
        for n in [12, 3, 12] {
            (b.0)(scenes(n)).unwrap();
        }
        assert_eq!(*seen.lock().unwrap(), vec![12, 3, 12]);
        let notes = notes.lock().unwrap();
        assert_eq!(notes.len(), 1, "{notes:?}");
        assert!(
            notes[0].contains("a batch of 12 evaluations"),
            "{}",
            notes[0]
        );
        assert!(notes[0].contains("--population"), "{}", notes[0]);
    }

    #[test]
    fn a_first_batch_of_thousands_is_not_noted_nor_a_small_one_after_it() {
        let (b, seen, notes) = counting();
        (b.0)(scenes(SMALL_BATCH)).unwrap();
        (b.0)(scenes(7)).unwrap();
        assert_eq!(*seen.lock().unwrap(), vec![SMALL_BATCH, 7]);
        assert!(notes.lock().unwrap().is_empty());
    }
}
