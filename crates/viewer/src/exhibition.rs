//! Watching an evolution: the current best roobot of every lane hopping side
//! by side, as the thesis's `HopEvolver` showed its champions.
//!
//! Each lane's roobot runs in its own evaluation world, exactly as its
//! fitness was measured (same floor, air, step and integrator), shifted
//! sideways for display. When it falls, over-stretches its leg or reaches
//! the evaluation's end, it starts again with whatever its lane's best is by
//! then. The evolution publishes its bests through a [`Showcase`].

use crate::protocol::{CreatureState, Describe, Part};
use animats_creatures::roobot::evaluate::{evaluation_world, EvalSettings};
use animats_creatures::roobot::{HopParams, Roobot};
use animats_creatures::Actor;
use animats_engine::{DVec3, World};
use animats_view::{framing, Stage};
use std::sync::{Arc, Mutex, PoisonError};

/// Sideways distance between lanes, m.
pub const LANE_SPACING: f64 = 1.0;
const PARTS: [&str; 5] = ["hip", "foot", "head", "tail1", "tail2"];

#[derive(Clone, Debug, Default)]
struct Board {
    best: Vec<Option<(HopParams, f64)>>,
    generation: u64,
    generations: u64,
}

/// The evolution's current bests, shared between the evolving thread and
/// the viewer.
#[derive(Clone, Debug, Default)]
pub struct Showcase(Arc<Mutex<Board>>);

impl Showcase {
    /// No bests yet for `lanes` lanes.
    pub fn new(lanes: usize) -> Showcase {
        Showcase(Arc::new(Mutex::new(Board {
            best: vec![None; lanes],
            ..Board::default()
        })))
    }

    fn board(&self) -> std::sync::MutexGuard<'_, Board> {
        // A panic elsewhere cannot leave a board half-written: every field
        // is assigned whole.
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Records lane `lane`'s best so far.
    pub fn set_best(&self, lane: usize, params: HopParams, fitness: f64) {
        if let Some(slot) = self.board().best.get_mut(lane) {
            *slot = Some((params, fitness));
        }
    }

    /// Records the progress of the run.
    pub fn set_generation(&self, generation: u64, generations: u64) {
        let mut b = self.board();
        b.generation = generation;
        b.generations = generations;
    }

    fn best(&self, lane: usize) -> Option<(HopParams, f64)> {
        self.board().best.get(lane).copied().flatten()
    }

    fn lanes(&self) -> usize {
        self.board().best.len()
    }
}

struct Lane {
    world: World,
    roobot: Roobot,
    fitness: Option<f64>,
}

/// Every lane's champion, hopping.
pub struct Exhibition {
    showcase: Showcase,
    settings: EvalSettings,
    lanes: Vec<Lane>,
    time: f64,
}

impl Exhibition {
    /// An exhibition of `showcase`'s lanes, evaluated with `settings`.
    pub fn new(showcase: Showcase, settings: EvalSettings) -> Result<Exhibition, String> {
        let mut e = Exhibition {
            settings,
            lanes: Vec::new(),
            time: 0.0,
            showcase,
        };
        for k in 0..e.showcase.lanes() {
            let lane = e.start(k)?;
            e.lanes.push(lane);
        }
        Ok(e)
    }

    /// A fresh evaluation world for lane `k` with its current best (the
    /// starting parameters until it has one).
    fn start(&self, k: usize) -> Result<Lane, String> {
        let (params, fitness) = match self.showcase.best(k) {
            Some((p, f)) => (p, Some(f)),
            None => (HopParams::INITIAL, None),
        };
        let (world, roobot) =
            evaluation_world(params, &self.settings).map_err(|e| e.to_string())?;
        Ok(Lane {
            world,
            roobot,
            fitness,
        })
    }

    fn offset(k: usize) -> DVec3 {
        DVec3::new(0.0, 0.0, k as f64 * LANE_SPACING)
    }

    fn finished(&self, lane: &Lane) -> bool {
        animats_creatures::roobot::evaluate::ended(&lane.world, &lane.roobot, &self.settings)
            .is_some()
            || lane.world.time() >= self.settings.seconds - 0.5 * self.settings.dt
    }
}

impl Stage for Exhibition {
    fn describe(&self) -> Describe {
        let mut particles = Vec::new();
        let mut springs = Vec::new();
        let mut pos = Vec::new();
        let mut labels = Vec::new();
        for (k, lane) in self.lanes.iter().enumerate() {
            let first = particles.len();
            // Above its hip (the first part).
            labels.push(animats_view::model::Label {
                text: format!("lane {k}"),
                particle: first,
            });
            let w = &lane.world;
            for (i, r) in w.particles().radius.iter().enumerate() {
                particles.push(Part {
                    name: format!("lane{k}.{}", PARTS.get(i).unwrap_or(&"part")),
                    radius: *r,
                    kind: "roobot".into(),
                });
            }
            springs.extend(w.forces().springs.iter().map(|s| {
                let (a, b) = s.ends();
                [first + a.index(), first + b.index()]
            }));
            pos.extend(w.state().pos.iter().map(|p| *p + Self::offset(k)));
        }
        let (target, distance) = framing(&pos, true);
        Describe {
            kind: "scene",
            title: format!(
                "evolution: the best roobot of each of {} lanes",
                self.lanes.len()
            ),
            particles,
            springs,
            fluid: None,
            floor: true,
            domes: Vec::new(),
            food: None,
            target,
            distance: distance.max(3.0),
            palette: animats_view::palette::PALETTE.into_iter().collect(),
            labels,
            orbit: true,
        }
    }

    fn dt(&self) -> f64 {
        self.settings.dt
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn step(&mut self, dt: f64) -> Result<(), String> {
        for k in 0..self.lanes.len() {
            let restart = self.finished(&self.lanes[k]) || {
                let lane = &mut self.lanes[k];
                lane.roobot.act(&mut lane.world, dt);
                // A blow-up ends that roobot's run, as it ends an evaluation.
                lane.world.step(dt).is_err()
            };
            if restart {
                self.lanes[k] = self.start(k)?;
            }
        }
        self.time += dt;
        Ok(())
    }

    fn positions(&self, out: &mut Vec<f32>) {
        out.clear();
        for (k, lane) in self.lanes.iter().enumerate() {
            for p in &lane.world.state().pos {
                let p = *p + Self::offset(k);
                out.extend([p.x as f32, p.y as f32, p.z as f32]);
            }
        }
    }

    fn creatures(&self) -> Vec<CreatureState> {
        self.lanes
            .iter()
            .enumerate()
            .map(|(k, lane)| CreatureState {
                name: match lane.fitness {
                    Some(f) => format!("lane {k} (fitness {f:.1})"),
                    None => format!("lane {k} (initial)"),
                },
                state: lane.roobot.fsm.state().name(),
                energy: None,
                phase: None,
            })
            .collect()
    }

    fn focus(&self) -> Option<[f64; 3]> {
        let (k, lane) = self.lanes.iter().enumerate().max_by(|a, b| {
            let x = |l: &Lane| l.world.position(l.roobot.body.hip).x;
            x(a.1).total_cmp(&x(b.1))
        })?;
        let p = lane.world.position(lane.roobot.body.hip) + Self::offset(k);
        // Aim at the middle of the lanes, level with the leader.
        let mid = 0.5 * (self.lanes.len().saturating_sub(1)) as f64 * LANE_SPACING;
        Some([p.x, 0.5, mid])
    }

    fn note(&self) -> Option<String> {
        let b = self.showcase.board();
        let best = b
            .best
            .iter()
            .enumerate()
            .filter_map(|(k, x)| x.map(|(_, f)| (k, f)))
            .max_by(|a, b| a.1.total_cmp(&b.1));
        Some(match best {
            Some((k, f)) => format!(
                "generation {} of {}: best fitness {f:.2} (lane {k})",
                b.generation, b.generations
            ),
            None => format!("generation {} of {}", b.generation, b.generations),
        })
    }

    fn reset(&mut self) -> Result<(), String> {
        for k in 0..self.lanes.len() {
            self.lanes[k] = self.start(k)?;
        }
        self.time = 0.0;
        Ok(())
    }
}
