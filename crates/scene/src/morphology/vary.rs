//! Variation: random bodies, mutation and crossover, for both encodings.
//! None of these checks what it makes (the caller does, [`super::check`],
//! retrying up to [`RETRIES`] times); each keeps every gene inside its
//! range, so that a refusal is about the body's shape, not a stray number.
//!
//! Graph mutations (one to three a child): add a particle (joined to its
//! two or three nearest), remove one (with its springs), add or remove a
//! spring, move a particle, change a mass, a radius or a stiffness, turn a
//! spring into a muscle or back, change a muscle's genes (a `neural`
//! body's touch weights with them), change the frequency, or nudge every
//! muscle's genes and the frequency a little at once (the gait's local
//! search). Graph crossover exchanges spatial halves: a random plane
//! through each parent's centre keeps one side of the first and the other
//! side of the second (moved onto the first's centre), and every spring the
//! cut severed is rejoined to the nearest particle across it.
//!
//! Lattice mutation repaints each cell with probability 0.1 (at least one
//! cell; EvoGym's rate) and nudges muscle genes (a `neural` lattice's
//! touch weights with them); lattice crossover copies a random box of
//! cells from the second parent into the first.

use super::genome::{Body, Edge, Muscle, Node};
use super::lattice::{Lattice, Material, Shape};
use super::{Morphology, AMPLITUDE, DUTY, FREQUENCY, TOUCH};
use animats_creatures::random::Random;
use animats_engine::DVec3;
use std::f64::consts::PI;

/// Tries a variation gets before the parent is kept (EvoGym's rule).
pub const RETRIES: usize = 10;

/// A standard normal deviate (Box–Muller with libm: the same bits on every
/// platform).
pub fn normal(rng: &mut Random) -> f64 {
    let u1 = 1.0 - rng.uniform();
    let u2 = rng.uniform();
    (-2.0 * animats_engine::math::log(u1)).sqrt()
        * animats_engine::math::cos(std::f64::consts::TAU * u2)
}

/// A whole number in `lo..=hi`.
fn int(rng: &mut Random, lo: usize, hi: usize) -> usize {
    if hi <= lo {
        return lo;
    }
    (lo + (rng.uniform() * (hi - lo + 1) as f64) as usize).min(hi)
}

/// `x` nudged by a normal step of `scale` of the range, kept in the range.
fn nudge(rng: &mut Random, x: f64, (lo, hi): (f64, f64), scale: f64) -> f64 {
    (x + normal(rng) * scale * (hi - lo)).clamp(lo, hi)
}

/// Log-uniform in the range.
fn log_between(rng: &mut Random, (lo, hi): (f64, f64)) -> f64 {
    (animats_engine::math::exp(
        rng.between(animats_engine::math::log(lo), animats_engine::math::log(hi)),
    ))
    .clamp(lo, hi)
}

/// What a body's muscles carry besides amplitude, phase and offset.
#[derive(Clone, Copy)]
struct Extra {
    neural: bool,
    skewed: bool,
}

impl Extra {
    fn of(body: &Body) -> Extra {
        Extra {
            neural: body.neural,
            skewed: body.skewed,
        }
    }
}

/// A muscle with random genes; a `neural` one's touch weights start small
/// (a reflex evolution grows); a `skewed` one's duty is uniform in
/// [`DUTY`].
fn random_muscle(rng: &mut Random, extra: Extra) -> Muscle {
    let mut mu = Muscle {
        amplitude: rng.between(AMPLITUDE.0, AMPLITUDE.1),
        phase: rng.between(-PI, PI),
        offset: rng.between(0.2, 0.8),
        touch: [0.0; 2],
        duty: 0.5,
    };
    if extra.neural {
        mu.touch = [
            rng.between(0.25 * TOUCH.0, 0.25 * TOUCH.1),
            rng.between(0.25 * TOUCH.0, 0.25 * TOUCH.1),
        ];
    }
    if extra.skewed {
        mu.duty = rng.between(DUTY.0, DUTY.1);
    }
    mu
}

/// `mu`'s genes nudged by normal steps of `scale` of their ranges (the
/// phase by `phase_step` rad).
fn nudge_muscle(rng: &mut Random, mu: &mut Muscle, scale: f64, phase_step: f64, extra: Extra) {
    mu.amplitude = nudge(rng, mu.amplitude, AMPLITUDE, scale);
    mu.phase = wrap(mu.phase + phase_step * normal(rng));
    mu.offset = nudge(rng, mu.offset, (0.0, 1.0), scale);
    if extra.neural {
        for w in &mut mu.touch {
            *w = nudge(rng, *w, TOUCH, scale);
        }
    }
    if extra.skewed {
        mu.duty = nudge(rng, mu.duty, DUTY, scale);
    }
}

fn unit(rng: &mut Random) -> DVec3 {
    loop {
        let v = DVec3::new(normal(rng), normal(rng), normal(rng));
        let l = v.length();
        if l > 1e-9 {
            return v / l;
        }
    }
}

fn joined(body: &Body, a: usize, b: usize) -> bool {
    body.edges
        .iter()
        .any(|e| (e.a == a && e.b == b) || (e.a == b && e.b == a))
}

/// The `k` particles nearest to `at` among `candidates`, nearest first.
fn nearest(
    body: &Body,
    at: DVec3,
    candidates: impl Iterator<Item = usize>,
    k: usize,
) -> Vec<usize> {
    let mut c: Vec<(f64, usize)> = candidates
        .map(|i| ((body.nodes[i].position - at).length(), i))
        .collect();
    c.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    c.into_iter().take(k).map(|(_, i)| i).collect()
}

fn spring(rng: &mut Random, m: &Morphology, a: usize, b: usize) -> Edge {
    Edge {
        a,
        b,
        stiffness: log_between(rng, m.stiffness),
        muscle: (rng.uniform() < 0.5).then(|| {
            random_muscle(
                rng,
                Extra {
                    neural: m.neural,
                    skewed: m.skewed,
                },
            )
        }),
    }
}

/// A random body: 4 to 10 particles (within the caps) scattered in most
/// of the size cube, joined into a tree of nearest neighbours and then each
/// to its two nearest more, half the springs muscles.
pub fn random_body(m: &Morphology, rng: &mut Random) -> Body {
    let most = m.max_particles.min(m.max_springs + 1).min(10);
    let n = int(rng, 4.min(most), most).max(2);
    let r_hi = m.radius.1.min(m.size / 8.0).max(m.radius.0);
    let m_hi = m.mass.1.min(0.9 * m.total_mass / n as f64).max(m.mass.0);
    let room = (0.8 * m.size - 2.0 * r_hi).max(0.0);
    let mut body = Body {
        nodes: Vec::with_capacity(n),
        edges: Vec::new(),
        frequency: rng.between(0.5, 3.0),
        neural: m.neural,
        skewed: m.skewed,
    };
    for _ in 0..n {
        let radius = rng.between(m.radius.0, r_hi);
        let mut node = Node {
            position: DVec3::ZERO,
            mass: rng.between(m.mass.0, m_hi),
            radius,
        };
        for _ in 0..50 {
            node.position = DVec3::new(
                rng.uniform() * room,
                rng.uniform() * room,
                rng.uniform() * room,
            );
            let clear = body
                .nodes
                .iter()
                .all(|o| (o.position - node.position).length() >= o.radius + radius);
            if clear {
                break;
            }
        }
        body.nodes.push(node);
    }
    for i in 1..n {
        let to = nearest(&body, body.nodes[i].position, 0..i, 1)[0];
        let e = spring(rng, m, to, i);
        body.edges.push(e);
    }
    for i in 0..n {
        for j in nearest(&body, body.nodes[i].position, (0..n).filter(|&j| j != i), 2) {
            if body.edges.len() < m.max_springs && !joined(&body, i, j) {
                let e = spring(rng, m, i, j);
                body.edges.push(e);
            }
        }
    }
    if body.muscles() == 0 {
        let k = int(rng, 0, body.edges.len() - 1);
        body.edges[k].muscle = Some(random_muscle(rng, Extra::of(&body)));
    }
    body
}

/// A mutant of `parent`: one to three of the module's mutations.
pub fn mutate_body(parent: &Body, m: &Morphology, rng: &mut Random) -> Body {
    let mut body = parent.clone();
    let mut times = 1;
    while times < 3 && rng.uniform() < 0.5 {
        times += 1;
    }
    for _ in 0..times {
        mutate_once(&mut body, m, rng);
    }
    body
}

/// Weights of the mutations, in [`mutate_once`]'s order.
const WEIGHTS: [f64; 12] = [1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 1.0, 2.0, 1.0, 3.0];

fn mutate_once(body: &mut Body, m: &Morphology, rng: &mut Random) {
    let total: f64 = WEIGHTS.iter().sum();
    let mut pick = rng.uniform() * total;
    let mut op = 0;
    while op + 1 < WEIGHTS.len() && pick >= WEIGHTS[op] {
        pick -= WEIGHTS[op];
        op += 1;
    }
    let n = body.nodes.len();
    let s = body.edges.len();
    if n == 0 {
        return;
    }
    let node = int(rng, 0, n - 1);
    let edge = (s > 0).then(|| int(rng, 0, s - 1));
    match op {
        0 => add_node(body, m, rng, node),
        1 => remove_node(body, node),
        2 => {
            let other = int(rng, 0, n - 1);
            if other != node && !joined(body, node, other) {
                let e = spring(rng, m, node, other);
                body.edges.push(e);
            }
        }
        3 => {
            if let Some(k) = edge {
                body.edges.remove(k);
            }
        }
        4 => {
            let step = DVec3::new(normal(rng), normal(rng), normal(rng)) * (0.03 * m.size);
            body.nodes[node].position += step;
        }
        5 => body.nodes[node].mass = nudge(rng, body.nodes[node].mass, m.mass, 0.1),
        6 => body.nodes[node].radius = nudge(rng, body.nodes[node].radius, m.radius, 0.1),
        7 => {
            if let Some(k) = edge {
                let e = &mut body.edges[k];
                e.stiffness = (e.stiffness * animats_engine::math::exp(0.3 * normal(rng)))
                    .clamp(m.stiffness.0, m.stiffness.1);
            }
        }
        8 => {
            if let Some(k) = edge {
                let extra = Extra::of(body);
                let e = &mut body.edges[k];
                e.muscle = match e.muscle {
                    Some(_) => None,
                    None => Some(random_muscle(rng, extra)),
                };
            }
        }
        9 => {
            let muscles: Vec<usize> = (0..s).filter(|&k| body.edges[k].muscle.is_some()).collect();
            if let Some(&k) = muscles.get(int(rng, 0, muscles.len().max(1) - 1)) {
                let extra = Extra::of(body);
                if let Some(mu) = body.edges[k].muscle.as_mut() {
                    nudge_muscle(rng, mu, 0.1, 0.2 * PI, extra);
                }
            }
        }
        10 => body.frequency = nudge(rng, body.frequency, FREQUENCY, 0.05),
        _ => {
            // The whole brain at once, a little: every muscle's genes and
            // the frequency (a local search of the gait on a fixed body).
            let extra = Extra::of(body);
            for e in &mut body.edges {
                if let Some(mu) = e.muscle.as_mut() {
                    nudge_muscle(rng, mu, 0.03, 0.05 * PI, extra);
                }
            }
            body.frequency = nudge(rng, body.frequency, FREQUENCY, 0.01);
        }
    }
}

/// An angle into [−π, π].
pub(crate) fn wrap(x: f64) -> f64 {
    let y = animats_engine::math::remainder(x, 2.0 * PI);
    y.clamp(-PI, PI)
}

fn add_node(body: &mut Body, m: &Morphology, rng: &mut Random, near: usize) {
    let from = body.nodes[near];
    let radius = rng.between(m.radius.0, m.radius.1);
    let distance = rng.between(
        from.radius + radius,
        (from.radius + radius).max(0.3 * m.size),
    );
    let node = Node {
        position: from.position + unit(rng) * distance,
        mass: rng.between(m.mass.0, m.mass.1),
        radius,
    };
    let i = body.nodes.len();
    body.nodes.push(node);
    let k = int(rng, 2, 3);
    for j in nearest(body, node.position, 0..i, k) {
        let e = spring(rng, m, j, i);
        body.edges.push(e);
    }
}

fn remove_node(body: &mut Body, node: usize) {
    body.nodes.remove(node);
    body.edges.retain(|e| e.a != node && e.b != node);
    for e in &mut body.edges {
        if e.a > node {
            e.a -= 1;
        }
        if e.b > node {
            e.b -= 1;
        }
    }
}

fn centre(body: &Body) -> DVec3 {
    body.nodes.iter().map(|n| n.position).sum::<DVec3>() / body.nodes.len().max(1) as f64
}

/// A child of `a` and `b` by spatial halves (see the module).
pub fn cross_bodies(a: &Body, b: &Body, rng: &mut Random) -> Body {
    let normal_ = unit(rng);
    let (ca, cb) = (centre(a), centre(b));
    let keep_a: Vec<bool> = a
        .nodes
        .iter()
        .map(|n| (n.position - ca).dot(normal_) <= 0.0)
        .collect();
    let keep_b: Vec<bool> = b
        .nodes
        .iter()
        .map(|n| (n.position - cb).dot(normal_) > 0.0)
        .collect();
    let mut child = Body {
        nodes: Vec::new(),
        edges: Vec::new(),
        frequency: if rng.uniform() < 0.5 {
            a.frequency
        } else {
            b.frequency
        },
        neural: a.neural,
        skewed: a.skewed,
    };
    let mut index_a = vec![usize::MAX; a.nodes.len()];
    for (i, n) in a.nodes.iter().enumerate().filter(|(i, _)| keep_a[*i]) {
        index_a[i] = child.nodes.len();
        child.nodes.push(*n);
    }
    let first_b = child.nodes.len();
    let mut index_b = vec![usize::MAX; b.nodes.len()];
    for (i, n) in b.nodes.iter().enumerate().filter(|(i, _)| keep_b[*i]) {
        index_b[i] = child.nodes.len();
        child.nodes.push(Node {
            position: n.position - cb + ca,
            ..*n
        });
    }
    let last = child.nodes.len();
    let mut severed = Vec::new();
    for (edges, index, lo, hi) in [
        (&a.edges, &index_a, first_b, last),
        (&b.edges, &index_b, 0, first_b),
    ] {
        for e in edges {
            match (index[e.a], index[e.b]) {
                (x, y) if x != usize::MAX && y != usize::MAX => {
                    child.edges.push(Edge { a: x, b: y, ..*e })
                }
                (x, usize::MAX) | (usize::MAX, x) if x != usize::MAX => {
                    severed.push((x, *e, lo, hi))
                }
                _ => {}
            }
        }
    }
    for (x, e, lo, hi) in severed {
        let at = child.nodes[x].position;
        if let Some(&y) = nearest(&child, at, lo..hi, 1).first() {
            if !joined(&child, x, y) {
                child.edges.push(Edge { a: x, b: y, ..e });
            }
        }
    }
    child
}

/// A random lattice: each cell empty with probability 0.3, else a random
/// material; random muscle genes in every cell (and, if `neural`, touch
/// weights).
pub fn random_lattice(shape: &Shape, neural: bool, rng: &mut Random) -> Lattice {
    let materials = (0..shape.len())
        .map(|_| {
            if rng.uniform() < 0.3 {
                Material::Empty
            } else {
                Material::ALL[int(rng, 1, Material::ALL.len() - 1)]
            }
        })
        .collect();
    let muscles = (0..shape.len())
        .map(|_| {
            random_muscle(
                rng,
                Extra {
                    neural,
                    skewed: false,
                },
            )
        })
        .collect();
    Lattice {
        materials,
        muscles,
        frequency: rng.between(0.5, 3.0),
        neural,
    }
}

/// A lattice mutant (see the module).
pub fn mutate_lattice(parent: &Lattice, rng: &mut Random) -> Lattice {
    let mut l = parent.clone();
    let n = l.materials.len();
    let mut repainted = false;
    for c in 0..n {
        if rng.uniform() < 0.1 {
            l.materials[c] = Material::ALL[int(rng, 0, Material::ALL.len() - 1)];
            repainted = true;
        }
    }
    if !repainted {
        let c = int(rng, 0, n - 1);
        l.materials[c] = Material::ALL[int(rng, 0, Material::ALL.len() - 1)];
    }
    for _ in 0..int(rng, 0, 2) {
        let mu = &mut l.muscles[int(rng, 0, n - 1)];
        nudge_muscle(
            rng,
            mu,
            0.1,
            0.2 * PI,
            Extra {
                neural: parent.neural,
                skewed: false,
            },
        );
    }
    if rng.uniform() < 0.2 {
        l.frequency = nudge(rng, l.frequency, FREQUENCY, 0.05);
    }
    l
}

/// `a` with a random box of cells (materials and muscle genes) from `b`.
pub fn cross_lattices(a: &Lattice, b: &Lattice, shape: &Shape, rng: &mut Random) -> Lattice {
    let mut child = a.clone();
    let mut lo = [0usize; 3];
    let mut hi = [0usize; 3];
    for k in 0..3 {
        let (x, y) = (int(rng, 0, shape.cells[k]), int(rng, 0, shape.cells[k]));
        lo[k] = x.min(y);
        hi[k] = x.max(y).max(lo[k] + 1).min(shape.cells[k]);
    }
    for z in lo[2]..hi[2] {
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                let c = x + shape.cells[0] * (y + shape.cells[1] * z);
                child.materials[c] = b.materials[c];
                child.muscles[c] = b.muscles[c];
            }
        }
    }
    if rng.uniform() < 0.5 {
        child.frequency = b.frequency;
    }
    child
}
