//! From a parsed scene description to a world: every entry validated, every
//! particle name resolved, every mistake reported with its entry and field.

use crate::def::*;
use crate::entries::Builder;
use crate::error::SceneError;
use crate::nervous::Handles;
use crate::source::Source;
use crate::Scene;
use animats_engine::DVec3;
use animats_engine::{Gravity, ModelError, ParticleId, Shown, Targets, World};
use std::collections::HashMap;
use toml::Spanned;

/// The most particles a scene may make, all its entries together: far past
/// any scene that runs at a useful speed (cloth-128 has 16,384), and small
/// enough that building it cannot exhaust memory (about 1 kB a particle with
/// its name, springs and scratch space).
pub const MAX_PARTICLES: usize = 1_000_000;

/// At least as many particles as any built-in creature has.
pub(crate) const CREATURE_PARTICLES: usize = 64;

/// Refuses a count that would take the world past [`MAX_PARTICLES`], before
/// anything is allocated for it.
pub(crate) fn room(at: &At, field: &str, count: usize, world: &World) -> Result<(), SceneError> {
    let left = MAX_PARTICLES.saturating_sub(world.len());
    if count > left {
        return Err(at.err(
            field,
            format!(
                "{} would take the scene past its limit of {MAX_PARTICLES} particles ({} before it)",
                if field.is_empty() {
                    "this entry".to_string()
                } else {
                    format!("{count}")
                },
                world.len()
            ),
        ));
    }
    Ok(())
}

/// Where an entry came from, for error messages.
pub(crate) struct At<'s> {
    src: &'s Source<'s>,
    entry: String,
    /// Where the entry starts in the file: its line is counted only for an
    /// error (counting it for every entry made loading quadratic in the
    /// file's size: 35 s for a 16,384-particle cloth).
    offset: usize,
}

impl At<'_> {
    pub(crate) fn err(&self, field: &str, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.src.file.to_string(),
            line: Some(self.src.field_line(self.offset, field)),
            entry: Some(self.entry.clone()),
            field: (!field.is_empty()).then(|| field.to_string()),
            message: message.into(),
        }
    }

    pub(crate) fn model(&self, e: ModelError) -> SceneError {
        self.err(&e.field, e.reason)
    }

    pub(crate) fn finite(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        if x.is_finite() {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be a finite number, got {}", Shown(x))))
        }
    }

    pub(crate) fn positive(&self, field: &str, x: f64) -> Result<f64, SceneError> {
        self.finite(field, x)?;
        if x > 0.0 {
            Ok(x)
        } else {
            Err(self.err(field, format!("must be > 0, got {}", Shown(x))))
        }
    }

    pub(crate) fn vec3(&self, field: &str, v: [f64; 3]) -> Result<DVec3, SceneError> {
        if v.iter().all(|x| x.is_finite()) {
            Ok(DVec3::from_array(v))
        } else {
            Err(self.err(field, format!("must be finite, got {v:?}")))
        }
    }
}

pub(crate) fn at<'s, T>(
    src: &'s Source<'s>,
    entry: impl Into<String>,
    spanned: &Spanned<T>,
) -> At<'s> {
    At {
        src,
        entry: entry.into(),
        offset: spanned.span().start,
    }
}

/// Resolves particle names to handles.
pub(crate) struct Names {
    pub(crate) ids: HashMap<String, ParticleId>,
}

impl Names {
    pub(crate) fn one(&self, at: &At, field: &str, name: &str) -> Result<ParticleId, SceneError> {
        self.ids
            .get(name)
            .copied()
            .ok_or_else(|| at.err(field, format!("unknown particle `{name}`")))
    }

    pub(crate) fn targets(
        &self,
        at: &At,
        names: &Option<Vec<String>>,
    ) -> Result<Targets, SceneError> {
        match names {
            None => Ok(Targets::All),
            Some(list) => Ok(Targets::Only(self.list(at, "particles", list)?)),
        }
    }

    /// The particles `names`, each once: a particle named twice would be
    /// acted on (or counted) twice, and an n-body group would pull it
    /// towards itself at no distance.
    pub(crate) fn list(
        &self,
        at: &At,
        field: &str,
        names: &[String],
    ) -> Result<Vec<ParticleId>, SceneError> {
        let mut seen = std::collections::HashSet::new();
        if let Some(twice) = names.iter().find(|n| !seen.insert(n.as_str())) {
            return Err(at.err(field, format!("`{twice}` is listed twice")));
        }
        names.iter().map(|n| self.one(at, field, n)).collect()
    }
}

/// A particle name: non-empty, and safe to write unquoted in CSV and JSON.
pub(crate) fn check_name(at: &At, name: &str) -> Result<(), SceneError> {
    let ok = !name.is_empty()
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | ':' | '#' | '/'));
    if ok {
        Ok(())
    } else {
        Err(at.err(
            "name",
            format!("`{name}` is not a valid name: use letters, digits and _ - . : # /"),
        ))
    }
}

/// The `[world]` table, checked.
struct WorldTable {
    gravity: DVec3,
    /// `None`: `"auto"`.
    dt: Option<f64>,
    duration: f64,
    max_dt: Option<f64>,
    seed: u64,
}

/// An empty world set up as the `[world]` table says (integrator, solver,
/// gravity), and the table's run settings.
fn world_table(def: &SceneDef, src: &Source) -> Result<(World, WorldTable), SceneError> {
    let mut world = World::new();
    let wd = def
        .world
        .as_ref()
        .map(|w| w.get_ref().clone())
        .unwrap_or_default();
    let wat = match &def.world {
        Some(w) => at(src, "world", w),
        None => At {
            src,
            entry: "world".into(),
            offset: 0,
        },
    };
    let table = WorldTable {
        gravity: wat.vec3("gravity", wd.gravity)?,
        dt: match wd.dt {
            crate::def::StepDef::Seconds(d) => Some(wat.positive("dt", d)?),
            crate::def::StepDef::Auto => None,
        },
        duration: wat.positive("duration", wd.duration)?,
        max_dt: match wd.max_dt {
            Some(m) => Some(wat.positive("max_dt", m)?),
            None => None,
        },
        seed: wd.seed,
    };
    world.set_integrator(wd.integrator.into());
    let mut solver = world.solver();
    if let Some(tol) = wd.implicit_tolerance {
        solver.tolerance = wat.positive("implicit_tolerance", tol)?;
    }
    if let Some(n) = wd.implicit_max_iterations {
        solver.max_iterations = n;
    }
    world.set_solver(solver).map_err(|e| {
        let field = match e.field.as_str() {
            "tolerance" => "implicit_tolerance",
            _ => "implicit_max_iterations",
        };
        wat.err(field, e.reason)
    })?;
    if table.gravity != DVec3::ZERO {
        world
            .set_gravity_force(Some(Gravity::new(table.gravity)))
            .map_err(|e| wat.model(e))?;
    }
    Ok((world, table))
}

/// Builds the world a scene describes.
pub fn build(def: &SceneDef, src: &Source) -> Result<Scene, SceneError> {
    if let Some(m) = &def.morphology {
        return Err(at(src, "morphology", m).err(
            "",
            "a [morphology] scene describes bodies, not one: develop one first (`animats evolve`, or `animats_scene::parse`, which develops its starting body)",
        ));
    }
    let (world, table) = world_table(def, src)?;
    let mut cx = Builder {
        src,
        world,
        names: Names {
            ids: HashMap::new(),
        },
        list: Vec::with_capacity(def.particle.len()),
        kinds: Vec::with_capacity(def.particle.len()),
        creatures: Vec::new(),
        handles: Handles::default(),
        actors: Vec::new(),
        nervous: Default::default(),
        origins: Vec::new(),
        seed: table.seed,
        gravity: table.gravity,
        terrain: None,
    };
    crate::entries::build_all(def, &mut cx)?;
    if let Some(fluid) = &def.fluid {
        fluid
            .get_ref()
            .add_rods(&at(src, "fluid", fluid), &mut cx)?;
    }
    // `[terrain]` without `[floor]`: the floor's defaults, so shaped.
    if let (Some(terrain), Some(entry)) = (cx.terrain.take(), &def.terrain) {
        cx.world
            .add_floor(animats_engine::FloorDef {
                terrain,
                ..Default::default()
            })
            .map_err(|e| at(src, "terrain", entry).model(e))?;
    }
    let Builder {
        mut world,
        names,
        list: name_list,
        kinds,
        creatures,
        handles,
        actors,
        mut nervous,
        mut origins,
        ..
    } = cx;
    // `dt = "auto"`: the recommended step now the springs are known.
    let dt = table.dt.unwrap_or_else(|| {
        let most = crate::def::DEFAULT_DT;
        world
            .recommended_dt(world.integrator())
            .map_or(most, |r| r.min(most))
    });
    let actuator_warnings = crate::nervous::build(
        def,
        src,
        &names,
        &handles,
        &mut world,
        &mut nervous,
        &mut origins,
    )?;
    let evolve = match &def.evolve {
        Some(entry) => Some(crate::evaluate::EvolveSpec::build(
            &at(src, "evolve", entry),
            entry.get_ref(),
            &names,
            &nervous,
            &origins,
            &world,
            dt,
        )?),
        None => None,
    };
    let archive = match &def.archive {
        Some(entry) => Some(entry.get_ref().build(
            &at(src, "archive", entry),
            &names,
            evolve.as_ref(),
        )?),
        None => None,
    };
    let guard =
        animats_engine::DivergenceGuard::new(&world, !actors.is_empty() || !nervous.is_empty());
    let mut warnings = warnings(def, &world, &name_list, dt, world.terrain().is_some());
    warnings.extend(actuator_warnings);
    Ok(Scene {
        world,
        guard,
        warnings,
        names: name_list,
        kinds,
        creatures,
        dt,
        max_dt: table.max_dt.unwrap_or(dt),
        duration: table.duration,
        actors,
        nervous,
        evolve,
        archive,
        seed: table.seed,
    })
}

/// A warning when `dt` is past the step at which the world's integrator
/// keeps its springs stable ([`World::step_limit`]), naming the particle
/// where the bound is reached and its stiffest spring; `names` are the
/// particles' names. The scene's own step is checked when it loads, a step
/// or integrator from a command line by whoever takes it.
pub fn step_warning(world: &World, names: &[String], dt: f64) -> Option<String> {
    let kind = world.integrator();
    let limit = world.step_limit(kind).filter(|l| dt > l.dt)?;
    let (a, b) = world.forces().springs.get(limit.spring).ends();
    let name = |i: usize| names.get(i).map_or("?", String::as_str);
    Some(format!(
        "dt = {dt} s is {:.1} times the step at which {kind} can stay stable with the springs at particle `{}` (ω up to {:.1} rad/s; stable below {:.3e} s, set by the spring `{}`–`{}`): expect a blow-up",
        dt / limit.dt,
        name(limit.particle.index()),
        limit.omega,
        limit.dt,
        name(a.index()),
        name(b.index())
    ))
}

/// What is allowed but probably a mistake: see [`Scene::warnings`].
fn warnings(def: &SceneDef, world: &World, names: &[String], dt: f64, floor: bool) -> Vec<String> {
    let mut out = Vec::new();
    let p = world.particles();
    if floor {
        let flat = world.terrain().is_none_or(|t| t.is_flat());
        for (i, name) in names.iter().enumerate() {
            let depth = -world.clearance(animats_engine::ParticleId::from_index(i));
            if depth > 1e-9 && !p.fixed[i] {
                out.push(if flat {
                    format!("particle `{name}` starts {depth:.4} m inside the floor (its lowest point is below y = 0): the floor will push it out at once")
                } else {
                    format!("particle `{name}` starts {depth:.4} m inside the terrain: the floor will push it out at once")
                });
            }
        }
    }
    for (k, entry) in def.particle.iter().enumerate() {
        let q = entry.get_ref();
        if q.fixed && q.velocity.iter().any(|v| *v != 0.0) {
            out.push(format!(
                "particle[{k}] `{}` is fixed, so its velocity {:?} is ignored",
                q.name, q.velocity
            ));
        }
    }
    out.extend(step_warning(world, names, dt));
    out
}
