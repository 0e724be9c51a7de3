//! One fitness evaluation of a hopping gait, as the thesis's `HopEvolver`
//! runs it (§3.2.1.5, Eq. 17): a roobot starts standing at the origin facing
//! +x in air over the floor; RK4 at 8 ms; the run ends when the hip touches
//! the floor, the leg passes its length limit, or after 20 s.
//! `fitness = time upright + 50 × forward distance of the hip`.

use super::{BodyConstants, HopParams, Roobot};
use crate::controller::Actor;
use animats_engine::{DVec3, FloorDef, FluidMedium, IntegratorKind, ModelError, Targets, World};
use std::fmt;

/// How an evaluation is run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EvalSettings {
    /// Longest evaluation, s (thesis: 20).
    pub seconds: f64,
    /// Step, s (thesis: 0.008).
    pub dt: f64,
    /// Integrator (thesis: RK4).
    pub integrator: IntegratorKind,
    /// The body.
    pub constants: BodyConstants,
}

impl Default for EvalSettings {
    fn default() -> Self {
        EvalSettings {
            seconds: 20.0,
            dt: 0.008,
            integrator: IntegratorKind::Rk4,
            constants: BodyConstants::STANDARD,
        }
    }
}

/// Why an evaluation ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// The hip touched the floor.
    Fell,
    /// The leg stretched past its length limit.
    LegLimit,
    /// It stayed up for the whole time.
    Timeout,
    /// The simulation went non-finite (counted like a fall).
    BlewUp,
}

impl Ending {
    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Ending::Fell => "fell",
            Ending::LegLimit => "leg limit",
            Ending::Timeout => "timeout",
            Ending::BlewUp => "blew up",
        }
    }
}

impl fmt::Display for Ending {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The outcome of one evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Evaluation {
    /// time_up + 50 × distance.
    pub fitness: f64,
    /// Time upright, s.
    pub time_up: f64,
    /// Forward distance travelled by the hip, m.
    pub distance: f64,
    /// Completed hops (landings).
    pub hops: u32,
    /// Why it ended.
    pub ending: Ending,
}

impl Evaluation {
    /// Mean forward speed over the time upright, m/s.
    pub fn mean_speed(&self) -> f64 {
        if self.time_up > 0.0 {
            self.distance / self.time_up
        } else {
            0.0
        }
    }
}

/// The evaluation world: gravity, still air around the roobot, and the floor
/// of the thesis's `HopEvolver` (`Floor(0.01, 0.2)`: 1 cm collision envelope,
/// static friction below 0.2 m/s), with a roobot at the origin facing +x.
pub fn evaluation_world(
    params: HopParams,
    settings: &EvalSettings,
) -> Result<(World, Roobot), ModelError> {
    let mut world = World::new();
    world.set_integrator(settings.integrator);
    world.set_gravity(DVec3::new(0.0, -9.8, 0.0));
    let roobot = Roobot::build(
        &mut world,
        "roobot",
        &settings.constants,
        DVec3::ZERO,
        0.0,
        params,
    )?;
    world.add_fluid(FluidMedium::air())?;
    world.add_floor(FloorDef {
        envelope: 0.01,
        static_speed: 0.2,
        targets: Targets::All,
        ..FloorDef::default()
    })?;
    Ok((world, roobot))
}

/// Why an evaluation must end now, before the next step: the hip (or any
/// part but the foot) touches the floor, or the leg is past its length
/// limit. The timeout is the caller's step count. The one place this rule
/// is written: evaluations and the live exhibition both use it.
pub fn ended(world: &World, roobot: &Roobot, settings: &EvalSettings) -> Option<Ending> {
    if roobot.fallen(world) {
        Some(Ending::Fell)
    } else if roobot.body.leg_length(world) >= settings.constants.leg_limit {
        Some(Ending::LegLimit)
    } else {
        None
    }
}

/// Evaluates `params`; `observe` is called with the world after every step
/// (and once before the first), for trajectories and tests.
pub fn evaluate_with(
    params: HopParams,
    settings: &EvalSettings,
    observe: impl FnMut(&World, &Roobot),
) -> Result<Evaluation, ModelError> {
    evaluate_driven(
        params,
        settings,
        |world, roobot, dt| {
            let before = roobot.landings();
            roobot.act(world, dt);
            roobot.landings() > before
        },
        observe,
    )
}

/// One evaluation with any controller of the roobot's body: `control`
/// sets the actuators before every step and says whether the foot just
/// landed (the hops counted). The world, the end rule and the fitness are
/// the FSM's (`params` only set the FSM, which `control` may ignore).
pub fn evaluate_driven(
    params: HopParams,
    settings: &EvalSettings,
    mut control: impl FnMut(&mut World, &mut Roobot, f64) -> bool,
    mut observe: impl FnMut(&World, &Roobot),
) -> Result<Evaluation, ModelError> {
    let (mut world, mut roobot) = evaluation_world(params, settings)?;
    let forward = roobot.body.forward;
    let hip = roobot.body.hip;
    let x0 = world.position(hip).dot(forward);
    let steps = (settings.seconds / settings.dt).round() as u64;
    let (mut up, mut hops) = (0u64, 0u32);
    let mut ending = Ending::Timeout;
    observe(&world, &roobot);
    for _ in 0..steps {
        if let Some(end) = ended(&world, &roobot, settings) {
            ending = end;
            break;
        }
        hops += control(&mut world, &mut roobot, settings.dt) as u32;
        if world.step(settings.dt).is_err() {
            ending = Ending::BlewUp;
            break;
        }
        up += 1;
        observe(&world, &roobot);
    }
    let time_up = up as f64 * settings.dt;
    let distance = world.position(hip).dot(forward) - x0;
    Ok(Evaluation {
        fitness: time_up + 50.0 * distance,
        time_up,
        distance,
        hops,
        ending,
    })
}

/// Evaluates `params` (see [`evaluate_with`]).
pub fn evaluate(params: HopParams, settings: &EvalSettings) -> Result<Evaluation, ModelError> {
    evaluate_with(params, settings, |_, _| {})
}
