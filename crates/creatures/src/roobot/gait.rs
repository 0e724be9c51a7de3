//! What a hop looks like from outside: how long each stance lasts in the
//! FSM, and how far the foot slides while it is on the floor. `animats hop`
//! prints it; docs/ROOBOT.md quotes it (a gait that skated on the floor, or
//! skipped its stance, shows here).

use animats_engine::{DVec3, ParticleId, World};

/// A record of one evaluation's stances and ground contacts, fed one step at
/// a time by [`GaitLog::observe`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GaitLog {
    /// Duration of each completed FSM stance (state `stance`), s.
    pub stances: Vec<f64>,
    /// For each completed ground contact of the foot: its duration (s) and
    /// how far the foot moved along the floor meanwhile (m).
    pub contacts: Vec<(f64, f64)>,
    stance_since: Option<f64>,
    contact: Option<(f64, DVec3)>,
}

impl GaitLog {
    /// Records the state after a step at `world.time()`: where the
    /// roobot's `foot` is, and whether its brain is in stance.
    pub fn observe(&mut self, world: &World, foot: ParticleId, in_stance: bool) {
        let t = world.time();
        match (self.stance_since, in_stance) {
            (None, true) => self.stance_since = Some(t),
            (Some(t0), false) => {
                self.stances.push(t - t0);
                self.stance_since = None;
            }
            _ => {}
        }
        let down = super::foot_down(world, foot);
        let foot = world.position(foot);
        let flat = DVec3::new(foot.x, 0.0, foot.z);
        match (self.contact, down) {
            (None, true) => self.contact = Some((t, flat)),
            (Some((t0, x0)), false) => {
                self.contacts.push((t - t0, (flat - x0).length()));
                self.contact = None;
            }
            _ => {}
        }
    }

    /// (min, median, max) of the stance durations, s.
    pub fn stance_summary(&self) -> Option<(f64, f64, f64)> {
        summary(self.stances.clone())
    }

    /// (min, median, max) of the foot's slide during each contact, m.
    pub fn slide_summary(&self) -> Option<(f64, f64, f64)> {
        summary(self.contacts.iter().map(|c| c.1).collect())
    }

    /// (min, median, max) of the contact durations, s.
    pub fn contact_summary(&self) -> Option<(f64, f64, f64)> {
        summary(self.contacts.iter().map(|c| c.0).collect())
    }
}

fn summary(mut v: Vec<f64>) -> Option<(f64, f64, f64)> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some((v[0], v[v.len() / 2], v[v.len() - 1]))
}
