//! [`MorphologyProblem`]: a `[morphology]` scene as an evolution problem.
//! A genome (a `Vec<f64>`, [`super::genome`] or [`super::lattice`]'s
//! layout) develops into the scene's text with the body written in; that
//! text is parsed and evaluated exactly as `animats evaluate` would.

use super::check::{self, Refusal};
use super::develop::{self, Brain, NAME};
use super::genome::{Body, Edge, Muscle, Node};
use super::lattice::Lattice;
use super::{vary, EncodingName, Morphology};
use crate::build::at;
use crate::error::SceneError;
use crate::evaluate::{Evaluation, EvolveSpec, SceneProblem};
use crate::source::Source;
use animats_creatures::random::Random;
use animats_engine::DVec3;
use toml_edit::DocumentMut;

/// A body's size, for logs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyStats {
    /// Particles.
    pub particles: usize,
    /// Springs, muscles included.
    pub springs: usize,
    /// Muscles.
    pub muscles: usize,
    /// kg.
    pub mass: f64,
}

/// A scene whose bodies evolve: genome → scene text → evaluation.
#[derive(Clone, Debug)]
pub struct MorphologyProblem {
    file: String,
    base: DocumentMut,
    morphology: Morphology,
    start: Option<Vec<f64>>,
    spec: EvolveSpec,
    grid: Option<crate::archive::Grid>,
    /// Where its evaluations run in batches, if not on the engine here.
    batches: Option<crate::evaluate::Batches>,
}

/// An error in the text developed from the user's file, placed in that
/// file: in a table the user wrote (`[evolve]`), at the line where they
/// wrote the field; elsewhere (the body's generated entries) at no line,
/// since the developed text's lines are not the file's.
fn in_user_file(src: &Source, mut e: SceneError) -> SceneError {
    e.line = e
        .entry
        .as_deref()
        .and_then(|t| src.table_offset(t))
        .map(|o| src.field_line(o, e.field.as_deref().unwrap_or("")));
    e
}

impl MorphologyProblem {
    /// Parses and checks a scene with a `[morphology]` table: every key,
    /// the rest of the scene (built once without a body), the start body
    /// if one is named, and the `[evolve]` table on a body developed into
    /// the scene.
    pub fn parse(text: &str, file: &str) -> Result<MorphologyProblem, SceneError> {
        let src = Source { file, text };
        let mut def = crate::parse_def(&src)?;
        let entry = def
            .morphology
            .take()
            .ok_or_else(|| SceneError::file(file, "the scene has no [morphology] table"))?;
        let here = at(&src, "morphology", &entry);
        let morphology = Morphology::from_entry(&here, entry.get_ref())?;
        if let Some(e) = &def.evolve {
            if e.get_ref().controller.as_deref().is_some_and(|c| c != NAME) {
                return Err(at(&src, "evolve", e).err(
                    "controller",
                    format!("a [morphology] scene evolves its body's own controller, `{NAME}`: leave the key out"),
                ));
            }
        }
        if morphology.neural && def.floor.is_none() {
            return Err(here.err(
                "controller",
                "`neural` bodies feel the floor through touch sensors, and this scene has no [floor]: use `oscillator`",
            ));
        }
        // The rest of the scene, checked where the user wrote it (the
        // archive's grid here, its measures on a developed body below).
        let grid = match def.archive.take() {
            Some(a) => Some(a.get_ref().grid(&at(&src, "archive", &a))?),
            None => None,
        };
        def.evolve = None;
        crate::build::build(&def, &src)?;
        let mut base: DocumentMut = text
            .parse()
            .map_err(|e| SceneError::file(file, format!("{e}")))?;
        base.remove("morphology");
        let start = match (&entry.get_ref().start[..], morphology.encoding) {
            ("random", EncodingName::Graph) => None,
            ("random", EncodingName::Lattice) => morphology.lattice.as_ref().and_then(|s| {
                s.start.as_ref().map(|materials| {
                    Lattice {
                        materials: materials.clone(),
                        muscles: vec![
                            Muscle {
                                amplitude: 0.25,
                                phase: 0.0,
                                offset: 0.5,
                                touch: [0.0; 2],
                                duty: 0.5,
                            };
                            s.len()
                        ],
                        frequency: 1.0,
                        neural: morphology.neural,
                    }
                    .to_genes(s)
                })
            }),
            (path, EncodingName::Graph) => {
                let mut body = start_body(file, path).map_err(|m| here.err("start", m))?;
                // A start's skewed waves would be lost on a sine body (a
                // neural body replaces the whole oscillator).
                if body.skewed && !morphology.skewed && !morphology.neural {
                    return Err(here.err(
                        "start",
                        format!(
                            "`{path}`'s oscillator has `duty` (skewed waves), for which a sine body has no genes: add `waveform = \"skewed\"`"
                        ),
                    ));
                }
                body.neural = morphology.neural;
                body.skewed = morphology.skewed;
                Some(body.to_genes())
            }
            (_, EncodingName::Lattice) => {
                return Err(here.err(
                    "start",
                    "a lattice starts from `random` (give `structure` for a starting body)",
                ))
            }
        };
        let mut problem = MorphologyProblem {
            file: file.to_string(),
            base,
            morphology,
            start,
            spec: placeholder_spec(),
            grid,
            batches: None,
        };
        // The start body's checks other than its settle first (their
        // reasons say more than a failed development would), then the
        // [evolve] table on it (or on a random body), which bounds the
        // steps: a step too small for the evaluation is refused before the
        // settle would take as many of them. The settle last.
        let refused = |problem: &MorphologyProblem, g: &[f64], r: Refusal| {
            // A settle that blew up at a step past the body's own
            // stability limit: say so.
            let why = match r {
                Refusal::SettleBlowUp => problem
                    .develop(g, "")
                    .ok()
                    .and_then(|t| crate::parse(&t, file).ok())
                    .and_then(|s| crate::build::step_warning(&s.world, &s.names, s.dt))
                    .map(|w| format!(" ({w})")),
                _ => None,
            };
            here.err(
                "start",
                format!(
                    "the starting body fails its own checks: {r}{}",
                    why.unwrap_or_default()
                ),
            )
        };
        if let Some(g) = &problem.start {
            let body = problem
                .body(g)
                .map_err(|_| refused(&problem, g, Refusal::Malformed))?;
            check::static_checks(&body, &problem.morphology)
                .map_err(|r| refused(&problem, g, r))?;
        }
        let probe = match &problem.start {
            Some(g) => g.clone(),
            None => problem.random(&mut Random::for_entry(0, 0)),
        };
        let text = problem
            .develop(&probe, "")
            .map_err(|m| SceneError::file(file, m))?;
        let scene = SceneProblem::parse(&text, file).map_err(|e| in_user_file(&src, e))?;
        problem.spec = scene.spec().clone();
        if let Some(g) = &problem.start {
            problem.check(g).map_err(|r| refused(&problem, g, r))?;
        }
        Ok(problem)
    }

    /// The problem with its evaluations run in `batches`.
    pub fn on(mut self, batches: Option<crate::evaluate::Batches>) -> MorphologyProblem {
        self.batches = batches;
        self
    }

    /// Where its evaluations run in batches, if not on the engine here.
    pub fn batches(&self) -> Option<&crate::evaluate::Batches> {
        self.batches.as_ref()
    }

    /// The scene file's name.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The `[morphology]` table, checked.
    pub fn morphology(&self) -> &Morphology {
        &self.morphology
    }

    /// The `[evolve]` table, as resolved on a developed body (duration,
    /// weights, lanes, robust: the same for every body).
    pub fn spec(&self) -> &EvolveSpec {
        &self.spec
    }

    /// The `[archive]` table's grid and settings, if the scene has one.
    pub fn grid(&self) -> Option<&crate::archive::Grid> {
        self.grid.as_ref()
    }

    /// A warning when `dt` is past the step at which `kind` keeps stable
    /// the stiffest spring the budgets allow between two of their lightest
    /// particles (`ω = √(2k/m)`, the pair's own mode: a body that has one
    /// vibrates at least that fast): then some bodies will blow up, at
    /// any seed. The base scene's own check cannot see this (it has no
    /// body), nor does one developed body speak for the rest.
    pub fn step_warning(&self, dt: f64, kind: animats_engine::IntegratorKind) -> Option<String> {
        let m = &self.morphology;
        let (lightest, what) = match &m.lattice {
            Some(shape) => (
                m.total_mass / (8.0 * shape.len() as f64),
                "two corners of one cell",
            ),
            None => (m.mass.0, "two of the lightest particles they allow"),
        };
        let k = m.stiffness.1;
        let omega = (2.0 * k / lightest).sqrt();
        let limit = kind.stable_omega_h() / omega;
        (dt > limit).then(|| {
            format!(
                "dt = {dt} s is {:.1} times the step at which {kind} keeps stable the stiffest spring the budgets allow ({k} N/m) between {what} ({lightest} kg each): ω = {omega:.1} rad/s, stable below {limit:.3e} s; expect some bodies to blow up (they keep none of their forward distance and enter no archive cell)",
                dt / limit
            )
        })
    }

    /// The starting body's genes, if the scene names one.
    pub fn start(&self) -> Option<&[f64]> {
        self.start.as_deref()
    }

    /// The body a genome encodes.
    pub fn body(&self, genes: &[f64]) -> Result<Body, String> {
        match &self.morphology.lattice {
            None => Body::from_genes(genes),
            Some(shape) => Ok(Lattice::from_genes(genes, shape)?.develop(shape, &self.morphology)),
        }
    }

    /// The scene with the body of `genes` written in, preceded by
    /// `comment`: what `best.toml` holds.
    pub fn develop(&self, genes: &[f64], comment: &str) -> Result<String, String> {
        let body = self.body(genes)?;
        develop::develop(&self.base, &body, &self.morphology, Brain::Driven, comment)
    }

    /// Evaluates the body of `genes` (a body the checks would refuse is
    /// still evaluated: the checks are the optimiser's business).
    pub fn evaluate(&self, genes: &[f64]) -> Result<Evaluation, String> {
        self.evaluate_screened(genes, &|_| true)
    }

    /// [`MorphologyProblem::evaluate`], the half-step run of a robust
    /// evaluation made only where `fine` says
    /// ([`crate::evaluate::score_screened`]).
    pub fn evaluate_screened(
        &self,
        genes: &[f64],
        fine: &dyn Fn(&Evaluation) -> bool,
    ) -> Result<Evaluation, String> {
        let text = self.develop(genes, "")?;
        let problem = SceneProblem::parse(&text, &self.file).map_err(|e| e.to_string())?;
        problem.evaluate_screened(problem.start(), fine)
    }

    /// [`MorphologyProblem::evaluate_screened`] on every genome of
    /// `genomes`, in batches run by `run` ([`crate::evaluate::score_all`]).
    pub fn evaluate_all(
        &self,
        genomes: &[Vec<f64>],
        fine: &dyn Fn(usize, &Evaluation) -> bool,
        run: &crate::evaluate::Runner,
    ) -> Result<Vec<Evaluation>, String> {
        use rayon::prelude::*;
        let problems = genomes
            .par_iter()
            .map(|g| {
                let text = self.develop(g, "")?;
                SceneProblem::parse(&text, &self.file).map_err(|e| e.to_string())
            })
            // (The first genome's failure, whichever thread failed first.)
            .collect::<Vec<_>>()
            .into_iter()
            .collect::<Result<Vec<_>, String>>()?;
        let makes: Vec<_> = problems
            .iter()
            .map(|p| move || p.scene(p.start()))
            .collect();
        let makes: Vec<&crate::evaluate::Make<'_>> = makes
            .iter()
            .map(|m| m as &crate::evaluate::Make<'_>)
            .collect();
        crate::evaluate::score_all(&makes, fine, run)
    }

    /// Every check of [`super::check`], the settle last.
    pub fn check(&self, genes: &[f64]) -> Result<(), Refusal> {
        let body = self.body(genes).map_err(|_| Refusal::Malformed)?;
        check::static_checks(&body, &self.morphology)?;
        let text = develop::develop(&self.base, &body, &self.morphology, Brain::Held, "")
            .map_err(|_| Refusal::Malformed)?;
        let mut scene = crate::parse(&text, &self.file).map_err(|_| Refusal::SettleBlowUp)?;
        let ids = (0..body.nodes.len())
            .map(|i| scene.particle(&format!("{NAME}.p{i}")))
            .collect::<Option<Vec<_>>>()
            .ok_or(Refusal::Malformed)?;
        let springs: Vec<(usize, usize)> = body.edges.iter().map(|e| (e.a, e.b)).collect();
        check::settle(&mut scene, &ids, &springs)
    }

    /// A random body's genes.
    pub fn random(&self, rng: &mut Random) -> Vec<f64> {
        match &self.morphology.lattice {
            None => vary::random_body(&self.morphology, rng).to_genes(),
            Some(shape) => vary::random_lattice(shape, self.morphology.neural, rng).to_genes(shape),
        }
    }

    /// A mutant of `parent` (malformed genes come back unchanged, to be
    /// refused by the checks).
    pub fn mutate(&self, parent: &[f64], rng: &mut Random) -> Vec<f64> {
        match &self.morphology.lattice {
            None => match Body::from_genes(parent) {
                Ok(b) => vary::mutate_body(&b, &self.morphology, rng).to_genes(),
                Err(_) => parent.to_vec(),
            },
            Some(shape) => match Lattice::from_genes(parent, shape) {
                Ok(l) => vary::mutate_lattice(&l, rng).to_genes(shape),
                Err(_) => parent.to_vec(),
            },
        }
    }

    /// A child of `a` and `b`.
    pub fn crossover(&self, a: &[f64], b: &[f64], rng: &mut Random) -> Vec<f64> {
        match &self.morphology.lattice {
            None => match (Body::from_genes(a), Body::from_genes(b)) {
                (Ok(x), Ok(y)) => vary::cross_bodies(&x, &y, rng).to_genes(),
                _ => a.to_vec(),
            },
            Some(shape) => match (Lattice::from_genes(a, shape), Lattice::from_genes(b, shape)) {
                (Ok(x), Ok(y)) => vary::cross_lattices(&x, &y, shape, rng).to_genes(shape),
                _ => a.to_vec(),
            },
        }
    }

    /// The size of the body `genes` encode.
    pub fn stats(&self, genes: &[f64]) -> Option<BodyStats> {
        let b = self.body(genes).ok()?;
        Some(BodyStats {
            particles: b.nodes.len(),
            springs: b.edges.len(),
            muscles: b.muscles(),
            mass: b.mass(),
        })
    }
}

/// A stand-in until the probe body's `[evolve]` is resolved.
fn placeholder_spec() -> EvolveSpec {
    EvolveSpec {
        controller: Some(NAME.into()),
        evolved: Vec::new(),
        duration: 1.0,
        particles: Vec::new(),
        axis: DVec3::X,
        distance_weight: 0.0,
        time_weight: 0.0,
        fail_on_touch: Vec::new(),
        touch_tolerance: 0.0,
        fail_on_stretch: Vec::new(),
        mutation: Default::default(),
        log: Default::default(),
        lanes: None,
        robust: false,
        robust_halvings: 1,
        optimiser: None,
        energy_weight: 0.0,
        target: None,
        trials: 1,
        noise: 0.0,
        aggregate: Default::default(),
        terms: Vec::new(),
    }
}

/// The body of the scene file at `path` (relative to `file`'s folder, else
/// to the working directory): its particles, its springs, and as muscles
/// the springs an actuator drives (their genes from an oscillator that
/// drives them, else amplitude 0.25, phase 0, offset 0.5); the frequency is
/// that oscillator's, else 1 Hz.
fn start_body(file: &str, path: &str) -> Result<Body, String> {
    let beside = std::path::Path::new(file)
        .parent()
        .map(|d| d.join(path))
        .filter(|p| p.exists());
    let path = beside.unwrap_or_else(|| std::path::PathBuf::from(path));
    let text = crate::read(&path).map_err(|e| e.to_string())?;
    let name = path.display().to_string();
    let def = crate::parse_def(&Source {
        file: &name,
        text: &text,
    })
    .map_err(|e| e.to_string())?;
    // (Its own start would be read in turn: a scene that starts from
    // itself recursed until the stack overflowed.)
    if def.morphology.is_some() {
        return Err(format!(
            "{name} has a [morphology] table of its own: a start body is a plain scene of [[particle]] and [[spring]] entries"
        ));
    }
    let scene = crate::parse(&text, &name).map_err(|e| e.to_string())?;
    let index = |p: &str| {
        def.particle
            .iter()
            .position(|q| q.get_ref().name == p)
            .ok_or_else(|| format!("{name}: spring end `{p}` is not a [[particle]] (a start body is made of [[particle]] and [[spring]] entries)"))
    };
    let nodes: Vec<Node> = def
        .particle
        .iter()
        .map(|p| {
            let p = p.get_ref();
            let id = scene
                .particle(&p.name)
                .ok_or(format!("{name}: no particle `{}`", p.name))?;
            Ok(Node {
                position: DVec3::from_array(p.position),
                mass: p.mass,
                radius: scene.world.particles().radius[id.index()],
            })
        })
        .collect::<Result<_, String>>()?;
    let oscillator = def.controller.iter().find_map(|c| match c.get_ref().get() {
        Ok(animats_creatures::brains::ControllerEntry::Oscillator(o)) => Some(o.clone()),
        _ => None,
    });
    let mut edges = Vec::new();
    for s in &def.spring {
        let s = s.get_ref();
        let driven = def.actuator.iter().find_map(|a| {
            let a = a.get_ref().get().ok()?;
            (matches!(&a.target, crate::def::Target::Spring(t) if Some(t) == s.name.as_ref()))
                .then(|| a.name.clone())
        });
        let muscle = driven.map(|actuator| {
            let k = oscillator
                .as_ref()
                .and_then(|o| o.outputs.iter().position(|x| *x == actuator));
            let pick = |v: &Option<Vec<f64>>, default: f64| {
                k.and_then(|k| v.as_ref().and_then(|v| v.get(k).copied()))
                    .unwrap_or(default)
            };
            let o = oscillator.as_ref();
            Muscle {
                amplitude: pick(&o.and_then(|o| o.amplitude.clone()), 0.25),
                phase: vary::wrap(pick(&o.and_then(|o| o.phase.clone()), 0.0)),
                offset: pick(&o.and_then(|o| o.offset.clone()), 0.5),
                touch: [0.0; 2],
                // (Outside `DUTY`, the start fails its checks, by name.)
                duty: pick(&o.and_then(|o| o.duty.clone()), 0.5),
            }
        });
        edges.push(Edge {
            a: index(&s.a)?,
            b: index(&s.b)?,
            stiffness: s.stiffness,
            muscle,
        });
    }
    let frequency = oscillator.as_ref().and_then(|o| o.frequency).unwrap_or(1.0);
    Ok(Body {
        nodes,
        edges,
        frequency,
        neural: false,
        // Whether the start's waves are skewed.
        skewed: oscillator.is_some_and(|o| o.duty.is_some()),
    })
}
