//! What is shown: a [`Stage`] advances a world and describes it.
//! [`SceneStage`] plays a scene file.
// std's transcendental functions: this code draws or benchmarks, off the step path
#![allow(clippy::disallowed_methods)]

use crate::model::{CreatureState, Describe, Dome, Part};
use animats_engine::DVec3;
use animats_scene::{PartKind, Scene};
use std::path::PathBuf;

/// Something the viewer can run and draw.
pub trait Stage: Send {
    /// What there is to draw.
    fn describe(&self) -> Describe;
    /// The step to advance by, s.
    fn dt(&self) -> f64;
    /// Simulated time, s.
    fn time(&self) -> f64;
    /// Advances by `dt`.
    fn step(&mut self, dt: f64) -> Result<(), String>;
    /// Whether a step from this thread goes to the thread pool (a large
    /// world: see `World::steps_on_pool`), so that a loop of steps should
    /// run inside `animats_engine::on_pool_if`.
    fn steps_on_pool(&self) -> bool {
        false
    }
    /// Writes every particle's position, x y z in order.
    fn positions(&self, out: &mut Vec<f32>);
    /// Every creature's state.
    fn creatures(&self) -> Vec<CreatureState>;
    /// The actuators' levels now, in scene order (muscles are coloured by
    /// them).
    fn levels(&self) -> Vec<f64> {
        Vec::new()
    }
    /// A point the camera may follow.
    fn focus(&self) -> Option<[f64; 3]> {
        None
    }
    /// A line about the run for the overlay.
    fn note(&self) -> Option<String> {
        None
    }
    /// Starts again from the beginning.
    fn reset(&mut self) -> Result<(), String>;
    /// Moves the food to (x, z); false if there is none.
    fn move_food(&mut self, _x: f64, _z: f64) -> bool {
        false
    }
}

/// A scene file, played live.
pub struct SceneStage {
    path: PathBuf,
    scene: Scene,
    /// The particles the camera frames and follows (see [`SceneStage::follow`]).
    focus: Vec<usize>,
    /// The `[evolve]` particles' centre at the start, if the scene has one.
    start: Option<DVec3>,
}

/// The `[evolve]` particles' centre in `scene`, if it has the table.
fn start_of(scene: &Scene) -> Option<DVec3> {
    scene.evolve.as_ref().map(|e| e.centre(&scene.world))
}

impl SceneStage {
    /// Loads the scene at `path`, framing and following its default focus.
    pub fn load(path: PathBuf) -> Result<SceneStage, String> {
        SceneStage::following(path, None)
    }

    /// Loads the scene at `path`; the camera frames and follows the
    /// creature or particle called `follow`, or by default the scene's
    /// `[evolve]` particles, or its creature if it has one (a roobot, a
    /// quadruped, a jellyfish...); a scene with none, or several, is framed
    /// whole and not followed.
    pub fn following(path: PathBuf, follow: Option<&str>) -> Result<SceneStage, String> {
        let scene = animats_scene::load(&path).map_err(|e| e.to_string())?;
        SceneStage::from_scene(path, scene, follow)
    }

    /// A scene already built (`path` names it), following as
    /// [`SceneStage::following`] does; a reset reloads `path`.
    pub fn from_scene(
        path: PathBuf,
        scene: Scene,
        follow: Option<&str>,
    ) -> Result<SceneStage, String> {
        let focus = focus_of(&scene, follow).map_err(|e| format!("{}: {e}", path.display()))?;
        let start = start_of(&scene);
        Ok(SceneStage {
            path,
            scene,
            focus,
            start,
        })
    }

    /// How the run stands against the scene's `[evolve]` table: the
    /// distance its particles' centre has gone along the axis, and the
    /// score of the time and that distance so far
    /// (`time_weight × t + distance_weight × d`, the fitness when the table
    /// weighs nothing else).
    pub fn progress(&self) -> Option<(f64, f64)> {
        let spec = self.scene.evolve.as_ref()?;
        let d = (spec.centre(&self.scene.world) - self.start?).dot(spec.axis);
        let t = self.scene.world.time();
        Some((d, spec.time_weight * t + spec.distance_weight * d))
    }

    /// [`SceneStage::progress`] as the overlay writes it.
    pub fn progress_note(&self) -> Option<String> {
        let (d, score) = self.progress()?;
        let spec = self.scene.evolve.as_ref()?;
        let plain = spec.energy_weight == 0.0 && spec.target.is_none() && spec.terms.is_empty();
        let label = if plain {
            "fitness"
        } else {
            "time and distance score"
        };
        Some(format!("distance {d:.2} m · {label} {score:.1}"))
    }

    /// The scene being played.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Indices of the particles followed (empty: none).
    pub fn followed(&self) -> &[usize] {
        &self.focus
    }

    /// The scene's warnings (see `animats_scene::Scene::warnings`).
    pub fn warnings(&self) -> &[String] {
        &self.scene.warnings
    }

    fn food(&self) -> Option<usize> {
        self.scene.kinds.iter().position(|k| *k == PartKind::Food)
    }
}

/// What the camera follows in `scene` (see [`SceneStage::following`]).
fn focus_of(scene: &Scene, follow: Option<&str>) -> Result<Vec<usize>, String> {
    if let Some(name) = follow {
        if let Some(c) = scene.creatures.iter().find(|c| c.name == name) {
            return Ok(c.particles.clone());
        }
        return match scene.particle(name) {
            Some(p) => Ok(vec![p.index()]),
            None => Err(format!(
                "--follow {name}: no creature or particle called `{name}`"
            )),
        };
    }
    if let Some(spec) = &scene.evolve {
        return Ok(spec.particles.iter().map(|p| p.index()).collect());
    }
    // One creature, whatever it is, is followed; among several (a
    // reef, a race) none is chosen over the others.
    Ok(match &scene.creatures[..] {
        [one] => one.particles.clone(),
        _ => Vec::new(),
    })
}

/// Where to point the camera at a set of positions: their middle, from a
/// distance that fits them, and the floor under them if there is one (what
/// falls lands in view).
pub fn framing(pos: &[DVec3], floor: bool) -> ([f64; 3], f64) {
    if pos.is_empty() {
        return ([0.0, 0.0, 0.0], 3.0);
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in pos {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if floor {
        lo.y = lo.y.min(0.0);
    }
    let c = (lo + hi) / 2.0;
    let size = (hi - lo).length().max(0.5);
    ([c.x, c.y.max(0.2), c.z], 1.2 * size + 0.5)
}

/// `animats render`'s close framing of a creature: the box around the
/// spheres (`(centre, radius)`) and, for a camera with a vertical field
/// of view of `fov` degrees on a picture `aspect` wide per unit high, the
/// distance at which the box fills 40 % of the width, or 60 % of the
/// height if that is the tighter (at least 0.3 m, as seen from the usual
/// direction); `None` without spheres.
pub fn snug(
    spheres: impl IntoIterator<Item = (DVec3, f64)>,
    fov: f64,
    aspect: f64,
) -> Option<(DVec3, f64)> {
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for (p, r) in spheres {
        lo = lo.min(p - DVec3::splat(r));
        hi = hi.max(p + DVec3::splat(r));
    }
    if !(lo.is_finite() && hi.is_finite()) {
        return None;
    }
    let extent = hi - lo;
    let across = DVec3::new(extent.x, 0.0, extent.z).length().max(0.05);
    let tall = extent.y.max(0.05);
    let tan = (0.5 * fov.to_radians()).tan();
    let distance = (across / (0.4 * 2.0 * tan * aspect))
        .max(tall / (0.6 * 2.0 * tan))
        .max(0.3);
    Some((0.5 * (lo + hi), distance))
}

/// [`snug`] over the `watched` particles of `scene` and every particle of
/// a creature that holds one, at `positions`: a scene whose fitness
/// watches a roobot's hip frames the whole roobot, not its hip alone.
pub fn snug_watched(
    scene: &Scene,
    watched: &[usize],
    positions: &[DVec3],
    fov: f64,
    aspect: f64,
) -> Option<(DVec3, f64)> {
    let mut framed = watched.to_vec();
    for c in &scene.creatures {
        if c.particles.iter().any(|p| watched.contains(p)) {
            framed.extend(&c.particles);
        }
    }
    framed.sort_unstable();
    framed.dedup();
    let radius = &scene.world.particles().radius;
    snug(
        framed
            .iter()
            .filter_map(|&i| Some((*positions.get(i)?, *radius.get(i)?))),
        fov,
        aspect,
    )
}

impl Stage for SceneStage {
    fn describe(&self) -> Describe {
        let w = &self.scene.world;
        let p = w.particles();
        let particles = (0..w.len())
            .map(|i| Part {
                name: self.scene.names[i].clone(),
                radius: p.radius[i],
                kind: self.scene.kinds[i].name(),
            })
            .collect();
        let springs = w
            .forces()
            .springs
            .iter()
            .map(|s| {
                let (a, b) = s.ends();
                [a.index(), b.index()]
            })
            .collect();
        let domes = self
            .scene
            .creatures
            .iter()
            .filter_map(|c| {
                let bell = c.bell.as_ref()?;
                Some(Dome {
                    name: c.name.clone(),
                    particles: bell.dome.clone(),
                    tentacles: bell.tentacles.clone(),
                })
            })
            .collect();
        let floor = w.event::<animats_engine::FloorCollision>().is_some();
        let pos = &w.state().pos;
        let (target, distance) = if self.focus.is_empty() {
            framing(pos, floor)
        } else {
            let followed: Vec<DVec3> = self.focus.iter().map(|&i| pos[i]).collect();
            // Room for the legs around the followed body and the ground it
            // crosses.
            let (target, distance) = framing(&followed, floor);
            (target, distance.max(1.6))
        };
        Describe {
            kind: "scene",
            title: self.path.display().to_string(),
            particles,
            springs,
            fluid: w.forces().fluids().first().map(|f| f.density),
            floor,
            domes,
            food: self.food(),
            target,
            distance,
            palette: crate::palette::PALETTE.into_iter().collect(),
            labels: Vec::new(),
            orbit: false,
            drawing: crate::drawing::Drawing::of(&self.scene, distance),
        }
    }

    fn dt(&self) -> f64 {
        self.scene.dt.min(self.scene.max_dt)
    }

    fn time(&self) -> f64 {
        self.scene.world.time()
    }

    fn steps_on_pool(&self) -> bool {
        self.scene.world.steps_on_pool()
    }

    /// With sleeping spheres (`[contacts] sleep_speed`), how many sleep;
    /// with `[evolve]`, the distance and fitness so far.
    fn note(&self) -> Option<String> {
        let sleep = self
            .scene
            .world
            .event::<animats_engine::SphereContact>()
            .filter(|c| c.def().sleep_speed > 0.0)
            .map(|c| {
                format!(
                    "{} spheres asleep, {} pairs touching",
                    c.sleeping(),
                    c.touching()
                )
            });
        match (sleep, self.progress_note()) {
            (Some(a), Some(b)) => Some(format!("{a} · {b}")),
            (a, b) => a.or(b),
        }
    }

    fn step(&mut self, dt: f64) -> Result<(), String> {
        self.scene.step(dt).map(|_| ()).map_err(|e| match e {
            animats_engine::SimError::NonFinite { particle, time } => format!(
                "particle `{}` went non-finite at t = {time} s (try a smaller step)",
                self.scene.name(particle)
            ),
            other => other.to_string(),
        })
    }

    fn positions(&self, out: &mut Vec<f32>) {
        out.clear();
        for p in &self.scene.world.state().pos {
            out.extend([p.x as f32, p.y as f32, p.z as f32]);
        }
    }

    fn levels(&self) -> Vec<f64> {
        self.scene.nervous.actuator_levels()
    }

    fn creatures(&self) -> Vec<CreatureState> {
        // Brains with states (an FSM's), then creatures acting on their own.
        let brains = self.scene.nervous.controllers.iter().filter_map(|c| {
            Some(CreatureState {
                name: c.name.clone(),
                state: c.brain.state()?.to_string(),
                energy: None,
                phase: None,
            })
        });
        let actors = self
            .scene
            .actors
            .iter()
            .filter_map(|a| a.status())
            .map(|s| CreatureState {
                name: s.name,
                state: s.state.to_string(),
                energy: s.energy,
                phase: s.phase,
            });
        brains.chain(actors).collect()
    }

    fn focus(&self) -> Option<[f64; 3]> {
        if self.focus.is_empty() {
            return None;
        }
        let pos = &self.scene.world.state().pos;
        let c = self.focus.iter().map(|&i| pos[i]).sum::<DVec3>() / self.focus.len() as f64;
        Some(c.to_array())
    }

    fn reset(&mut self) -> Result<(), String> {
        self.scene = animats_scene::load(&self.path).map_err(|e| e.to_string())?;
        self.start = start_of(&self.scene);
        Ok(())
    }

    fn move_food(&mut self, x: f64, z: f64) -> bool {
        match self.food() {
            Some(i) => {
                let id = animats_engine::ParticleId::from_index(i);
                let y = self.scene.world.position(id).y;
                self.scene
                    .world
                    .set_position(id, DVec3::new(x, y, z))
                    .is_ok()
            }
            None => false,
        }
    }
}
