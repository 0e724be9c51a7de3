//! What every body must pass before it is evaluated: a well-formed graph
//! (no spring joining a particle to itself, no two springs on one pair),
//! within every cap and budget, connected, no two spheres overlapping at
//! the start, at least one muscle, and a short passive settle
//! ([`SETTLE_SECONDS`] under the scene's gravity with every muscle held at
//! its built length) that neither blows up nor collapses flat.

use super::genome::Body;
use super::{EncodingName, Morphology, AMPLITUDE, DUTY, FREQUENCY, TOUCH};
use animats_engine::DVec3;
use std::collections::HashSet;
use std::fmt;

/// Seconds of the passive settle.
pub const SETTLE_SECONDS: f64 = 0.5;

/// A body that settles flatter than this fraction of its built height has
/// collapsed.
pub const FLAT: f64 = 0.25;

/// A spring stretched past this many times its built length during the
/// settle has blown up.
pub const TORN: f64 = 3.0;

/// Why a body was refused.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Refusal {
    /// Not a body: a spring joins a particle to itself or repeats a pair,
    /// or its genome is the other controller's.
    Malformed,
    /// Fewer than two particles, or more than `max_particles`.
    Particles,
    /// No spring, or more than `max_springs`.
    Springs,
    /// Heavier than `total_mass`, or a particle outside the `mass` range.
    Mass,
    /// A gene outside its range (stiffness, radius, a muscle's genes, the
    /// frequency).
    Range,
    /// Larger than `size` along some axis.
    Size,
    /// Not one connected piece.
    Disconnected,
    /// Two spheres overlap.
    Overlap,
    /// No muscle.
    NoMuscle,
    /// The settle blew up (a non-finite state, the divergence guard, a
    /// spring torn to [`TORN`] times its length).
    SettleBlowUp,
    /// The settle left it flatter than [`FLAT`] of its built height.
    SettleFlat,
}

impl Refusal {
    /// Every reason, in the order summaries list them.
    pub const ALL: [Refusal; 11] = [
        Refusal::Malformed,
        Refusal::Particles,
        Refusal::Springs,
        Refusal::Mass,
        Refusal::Range,
        Refusal::Size,
        Refusal::Disconnected,
        Refusal::Overlap,
        Refusal::NoMuscle,
        Refusal::SettleBlowUp,
        Refusal::SettleFlat,
    ];

    /// Its name in logs and summaries.
    pub fn name(&self) -> &'static str {
        match self {
            Refusal::Malformed => "malformed",
            Refusal::Particles => "particles",
            Refusal::Springs => "springs",
            Refusal::Mass => "mass",
            Refusal::Range => "range",
            Refusal::Size => "size",
            Refusal::Disconnected => "disconnected",
            Refusal::Overlap => "overlap",
            Refusal::NoMuscle => "no-muscle",
            Refusal::SettleBlowUp => "settle-blow-up",
            Refusal::SettleFlat => "settle-flat",
        }
    }
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

fn within(x: f64, (lo, hi): (f64, f64)) -> bool {
    x.is_finite() && lo <= x && x <= hi
}

/// The checks that need no simulation, cheapest first.
pub fn static_checks(body: &Body, m: &Morphology) -> Result<(), Refusal> {
    if body.neural != m.neural || body.skewed != m.skewed {
        return Err(Refusal::Malformed);
    }
    let n = body.nodes.len();
    if n < 2 || n > m.max_particles {
        return Err(Refusal::Particles);
    }
    if body.edges.is_empty() || body.edges.len() > m.max_springs {
        return Err(Refusal::Springs);
    }
    let mut pairs = HashSet::with_capacity(body.edges.len());
    for e in &body.edges {
        if e.a == e.b || e.a >= n || e.b >= n || !pairs.insert((e.a.min(e.b), e.a.max(e.b))) {
            return Err(Refusal::Malformed);
        }
    }
    let graph = m.encoding == EncodingName::Graph;
    let mass = body.mass();
    if mass.is_nan()
        || mass > m.total_mass * (1.0 + 1e-12)
        || (graph && body.nodes.iter().any(|p| !within(p.mass, m.mass)))
    {
        return Err(Refusal::Mass);
    }
    let genes_ok = within(body.frequency, FREQUENCY)
        && body
            .nodes
            .iter()
            .all(|p| within(p.radius, m.radius) && p.position.is_finite())
        && body.edges.iter().all(|e| {
            within(e.stiffness, m.stiffness)
                && e.muscle.is_none_or(|mu| {
                    within(mu.amplitude, AMPLITUDE)
                        && within(mu.phase, (-std::f64::consts::PI, std::f64::consts::PI))
                        && within(mu.offset, (0.0, 1.0))
                        && mu.touch.iter().all(|&w| within(w, TOUCH))
                        && within(mu.duty, DUTY)
                })
        });
    if !genes_ok {
        return Err(Refusal::Range);
    }
    let (lo, hi) = body.nodes.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(p.position - p.radius), hi.max(p.position + p.radius)),
    );
    if (hi - lo).max_element() > m.size * (1.0 + 1e-12) {
        return Err(Refusal::Size);
    }
    if !connected(body) {
        return Err(Refusal::Disconnected);
    }
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (&body.nodes[i], &body.nodes[j]);
            if (a.position - b.position).length() < a.radius + b.radius {
                return Err(Refusal::Overlap);
            }
        }
    }
    if body.muscles() == 0 {
        return Err(Refusal::NoMuscle);
    }
    Ok(())
}

/// Every particle reachable from the first along springs.
pub fn connected(body: &Body) -> bool {
    let n = body.nodes.len();
    let mut parent: Vec<usize> = (0..n).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for e in &body.edges {
        let (a, b) = (root(&mut parent, e.a), root(&mut parent, e.b));
        parent[a.max(b)] = a.min(b);
    }
    (0..n).all(|i| root(&mut parent, i) == 0)
}

/// The passive settle of `scene` (the body developed with its muscles
/// held, [`super::develop::Brain::Held`]): `body` are the body's particles
/// in the world, `springs` its springs as pairs of indices into `body`.
pub fn settle(
    scene: &mut crate::Scene,
    body: &[animats_engine::ParticleId],
    springs: &[(usize, usize)],
) -> Result<(), Refusal> {
    let dt = scene.dt;
    let steps = (SETTLE_SECONDS / dt).round().max(1.0) as u64;
    let at = |scene: &crate::Scene| -> Vec<DVec3> {
        body.iter().map(|&p| scene.world.position(p)).collect()
    };
    let height = |p: &[DVec3]| {
        let (lo, hi) = p
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x.y), hi.max(x.y))
            });
        hi - lo
    };
    let start = at(scene);
    let built = height(&start);
    for _ in 0..steps {
        if scene.step(dt).is_err() {
            return Err(Refusal::SettleBlowUp);
        }
    }
    let end = at(scene);
    let torn = springs.iter().any(|&(a, b)| {
        let l = (end[a] - end[b]).length();
        l.is_nan() || l > TORN * (start[a] - start[b]).length()
    });
    if torn || !end.iter().all(|p| p.is_finite()) {
        return Err(Refusal::SettleBlowUp);
    }
    if built > 0.0 && height(&end) < FLAT * built {
        return Err(Refusal::SettleFlat);
    }
    Ok(())
}
