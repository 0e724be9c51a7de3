//! Damped Hooke spring (thesis §3.1.2.2, Eq. 11): `F = k (l - r) + k_d dl/dt`
//! along the spring, equal and opposite on its ends. The rest length `r` may be
//! changed at run time: it is the muscle that actuators drive.

use crate::error::ModelError;
use crate::force::{Force, ForceContext};
use crate::parallel::take_front;
use crate::particle::{non_negative, ParticleId};
use glam::DVec3;

mod grid;
mod kernel;
mod threads;

/// Handle to one spring of a world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SpringId(pub(crate) u32);

impl SpringId {
    /// Index of the spring in the world's spring collection.
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Description of a spring to add to a world.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringDef {
    /// One end.
    pub a: ParticleId,
    /// The other end.
    pub b: ParticleId,
    /// Stiffness `k`, N/m, >= 0.
    pub stiffness: f64,
    /// Damping `k_d` along the spring, N s/m, >= 0.
    pub damping: f64,
    /// Rest length, m, > 0; `None` means the distance between the ends when
    /// the spring is added.
    pub rest_length: Option<f64>,
}

impl SpringDef {
    /// A spring between `a` and `b` at rest at its initial length.
    pub fn new(a: ParticleId, b: ParticleId, stiffness: f64, damping: f64) -> Self {
        SpringDef {
            a,
            b,
            stiffness,
            damping,
            rest_length: None,
        }
    }
    /// Sets the rest length.
    pub fn with_rest_length(mut self, rest_length: f64) -> Self {
        self.rest_length = Some(rest_length);
        self
    }
}

/// One spring: its ends and parameters (a copy; change a world's springs
/// with [`Springs::set_rest_length`] and the other setters).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spring {
    a: u32,
    b: u32,
    /// N/m.
    pub stiffness: f64,
    /// N s/m.
    pub damping: f64,
    /// m.
    pub rest_length: f64,
}

impl Spring {
    /// The two ends.
    pub fn ends(&self) -> (ParticleId, ParticleId) {
        (ParticleId(self.a), ParticleId(self.b))
    }

    /// Signed tension (positive when stretched) at the given state, N.
    pub fn tension(&self, pos: &[DVec3], vel: &[DVec3]) -> f64 {
        let (a, b) = (self.a as usize, self.b as usize);
        let d = pos[b] - pos[a];
        let len = d.length();
        let n = if len > 0.0 { d / len } else { DVec3::ZERO };
        self.stiffness * (len - self.rest_length) + self.damping * (vel[b] - vel[a]).dot(n)
    }
}

/// Every spring of a world, as separate arrays (ends, stiffness, damping,
/// rest length) so the force loop reads each parameter as a vector.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Springs {
    table: Table,
    scratch: Scratch,
}

/// The springs' arrays, all as long as each other.
#[derive(Clone, Debug, Default)]
struct Table {
    ends: Vec<[u32; 2]>,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    rest_length: Vec<f64>,
    /// The stiffness and damping of every spring, when all springs have the
    /// same (bit for bit): a mesh's usually do. The force loop then reads
    /// neither array, and a large mesh's springs stream half the bytes
    /// through the cache each evaluation.
    shared: Option<(f64, f64)>,
}

/// Tables are equal when their springs are: `shared` is a summary of them
/// that a table whose springs were changed and changed back may have
/// given up.
impl PartialEq for Table {
    fn eq(&self, other: &Self) -> bool {
        self.ends == other.ends
            && self.stiffness == other.stiffness
            && self.damping == other.damping
            && self.rest_length == other.rest_length
    }
}

/// Some consecutive springs of a [`Table`], borrowed.
#[derive(Clone, Copy)]
struct Slice<'a> {
    ends: &'a [[u32; 2]],
    stiffness: &'a [f64],
    damping: &'a [f64],
    rest_length: &'a [f64],
    /// [`Table::shared`].
    shared: Option<(f64, f64)>,
}

impl Table {
    fn all(&self) -> Slice<'_> {
        Slice {
            ends: &self.ends,
            stiffness: &self.stiffness,
            damping: &self.damping,
            rest_length: &self.rest_length,
            shared: self.shared,
        }
    }

    /// Keeps [`Table::shared`] true after spring `i`'s stiffness or damping
    /// changed (or it was added): it stays only while `i` has the shared
    /// values, and a first spring starts it.
    fn note(&mut self, i: usize) {
        let mine = (self.stiffness[i], self.damping[i]);
        let same =
            |(k, c): (f64, f64)| k.to_bits() == mine.0.to_bits() && c.to_bits() == mine.1.to_bits();
        self.shared = match self.shared {
            _ if self.ends.len() == 1 => Some(mine),
            Some(s) if same(s) => Some(s),
            _ => None,
        };
    }
}

impl<'a> Slice<'a> {
    fn len(&self) -> usize {
        self.ends.len()
    }

    /// Springs `range` of this slice.
    fn range(&self, range: std::ops::Range<usize>) -> Slice<'a> {
        Slice {
            ends: &self.ends[range.clone()],
            stiffness: &self.stiffness[range.clone()],
            damping: &self.damping[range.clone()],
            rest_length: &self.rest_length[range],
            shared: self.shared,
        }
    }

    /// The slice in pieces of at most `size` springs.
    fn chunks(self, size: usize) -> impl Iterator<Item = Slice<'a>> {
        (0..self.len())
            .step_by(size)
            .map(move |i| self.range(i..(i + size).min(self.len())))
    }
}

/// What the force loops keep between steps, so a step neither allocates nor
/// clears anything. It holds nothing a copy of the world needs: cloning,
/// comparing and printing ignore it.
#[derive(Default)]
struct Scratch {
    block: Option<Box<kernel::Block>>,
    parallel: threads::Parallel,
    /// The stages of the springs and particles counted in `stages.0`.
    stages: ((usize, usize), kernel::Stages),
    /// Whether the springs are a mesh's ([`grid::Grid`]), for the springs
    /// and particles counted in `.0`.
    grid: Option<((usize, usize), Option<grid::Grid>)>,
}

impl Clone for Scratch {
    fn clone(&self) -> Self {
        Scratch::default()
    }
}

impl PartialEq for Scratch {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for Scratch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Scratch")
    }
}

impl Springs {
    /// Number of springs.
    pub fn len(&self) -> usize {
        self.table.ends.len()
    }
    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.table.ends.is_empty()
    }
    /// The spring `id`.
    pub fn get(&self, id: SpringId) -> Spring {
        let (t, i) = (&self.table, id.index());
        Spring {
            a: t.ends[i][0],
            b: t.ends[i][1],
            stiffness: t.stiffness[i],
            damping: t.damping[i],
            rest_length: t.rest_length[i],
        }
    }
    /// Sets the rest length of spring `id` (the muscle's activation).
    #[inline]
    pub fn set_rest_length(&mut self, id: SpringId, rest_length: f64) {
        self.table.rest_length[id.index()] = rest_length;
        self.changed(id);
    }
    /// Sets the stiffness of spring `id`.
    #[inline]
    pub fn set_stiffness(&mut self, id: SpringId, stiffness: f64) {
        self.table.stiffness[id.index()] = stiffness;
        self.table.note(id.index());
        self.changed(id);
    }
    /// Sets the damping of spring `id`.
    #[inline]
    pub fn set_damping(&mut self, id: SpringId, damping: f64) {
        self.table.damping[id.index()] = damping;
        self.table.note(id.index());
        self.changed(id);
    }
    /// Keeps the mesh's copy of spring `id`'s parameters (if any) up to date.
    #[inline]
    fn changed(&mut self, id: SpringId) {
        if let Some((_, Some(grid))) = &mut self.scratch.grid {
            grid.set(self.table.all(), id.index());
        }
    }
    /// All springs, in the order they were added.
    pub fn iter(&self) -> impl Iterator<Item = Spring> + '_ {
        (0..self.len()).map(|i| self.get(SpringId(i as u32)))
    }

    /// Adds a spring; `pos` are the current positions (for the default rest length).
    pub(crate) fn add(&mut self, def: &SpringDef, pos: &[DVec3]) -> Result<SpringId, ModelError> {
        if def.a == def.b {
            return Err(ModelError::new(
                "b",
                "a spring needs two different particles",
            ));
        }
        non_negative("stiffness", def.stiffness)?;
        non_negative("damping", def.damping)?;
        let initial = (pos[def.b.index()] - pos[def.a.index()]).length();
        if initial == 0.0 {
            return Err(ModelError::new(
                "b",
                "the two ends start at the same point: a spring of zero length has no direction",
            ));
        }
        let rest_length = def.rest_length.unwrap_or(initial);
        non_negative("rest_length", rest_length)?;
        if rest_length == 0.0 {
            return Err(ModelError::new("rest_length", "must be > 0, got 0"));
        }
        let t = &mut self.table;
        t.ends.push([def.a.0, def.b.0]);
        t.stiffness.push(def.stiffness);
        t.damping.push(def.damping);
        t.rest_length.push(rest_length);
        t.note(t.ends.len() - 1);
        Ok(SpringId(self.len() as u32 - 1))
    }
}

impl Scratch {
    /// The springs' mesh, if they are one (found once for each count of
    /// springs and particles: a spring's ends never change).
    fn grid(&mut self, springs: Slice, particles: usize) -> Option<&mut grid::Grid> {
        let key = (springs.len(), particles);
        if self.grid.as_ref().is_none_or(|(k, _)| *k != key) {
            self.grid = Some((key, grid::Grid::find(springs, particles)));
        }
        self.grid.as_mut().and_then(|(_, g)| g.as_mut())
    }
}

impl Springs {
    /// True if the springs are split among threads ([`Self::apply_from`]
    /// can then set gravity in the same fork).
    #[inline]
    pub(crate) fn on_threads(&self) -> bool {
        self.len() >= threads::MIN_SPRINGS && rayon::current_num_threads() > 1
    }

    /// The threads the springs are summed on: the pool's, or one.
    fn threads(&self) -> usize {
        if self.on_threads() {
            rayon::current_num_threads()
        } else {
            1
        }
    }

    /// Whether [`Self::apply_then`] may be used: the springs in blocks.
    #[inline]
    pub(crate) fn can_apply_then(&self) -> bool {
        self.len() >= kernel::MIN_BLOCKED
    }

    /// [`Force::apply`] with no pass of its own over the particles before
    /// or after the springs: `start(range, forces)` sets the forces of each
    /// run of particles just before the first spring adds to them, and
    /// `then(first, forces, [x, v])` has a run's forces as soon as no
    /// later spring adds to them, with the same run of `outs` (`first` its
    /// first particle); each particle is started once and handed on once.
    /// On one thread the runs go in order from the first particle to the
    /// last; on many ([`Self::on_threads`]) each thread stages its own
    /// particles, and the few that several threads' springs share are
    /// handed on after the join. The answers of the runs are combined by
    /// `combine`, which must be associative and commutative (`None`: no
    /// particles).
    pub(crate) fn apply_then<R: Send>(
        &mut self,
        ctx: &ForceContext,
        forces: &mut [DVec3],
        start: impl Fn(std::ops::Range<usize>, &mut [DVec3]) + Sync,
        outs: [&mut [DVec3]; 2],
        then: impl Fn(usize, &[DVec3], [&mut [DVec3]; 2]) -> R + Sync,
        combine: impl Fn(R, R) -> R + Sync + Send,
    ) -> Option<R> {
        let springs = self.table.all();
        let threads = self.threads();
        if let Some(grid) = self.scratch.grid(springs, forces.len()) {
            return grid.run(
                springs, ctx.pos, ctx.vel, forces, threads, start, outs, then, combine,
            );
        }
        if self.on_threads() {
            let (pos, vel) = (ctx.pos, ctx.vel);
            let parallel = &mut self.scratch.parallel;
            return parallel.apply_then(springs, pos, vel, forces, start, outs, then, combine);
        }
        let key = (springs.len(), forces.len());
        let Scratch { block, stages, .. } = &mut self.scratch;
        if stages.0 != key {
            // A spring's ends never change: only a new spring or particle
            // calls for new stages.
            *stages = (key, kernel::Stages::new(springs.ends, forces.len()));
        }
        let block = block.get_or_insert_with(Box::default);
        let [mut x, mut v] = outs;
        let mut answer = None;
        let mut sink = kernel::Staged::new(
            kernel::Scatter::new(forces),
            &stages.1,
            |r, f| start(r, f),
            |r: std::ops::Range<usize>, f: &[DVec3]| {
                let out = [take_front(&mut x, r.len()), take_front(&mut v, r.len())];
                let a = then(r.start, f, out);
                answer = Some(match answer.take() {
                    Some(b) => combine(b, a),
                    None => a,
                });
            },
        );
        kernel::run(springs, block, ctx.pos, ctx.vel, &mut sink);
        answer
    }

    /// [`Force::apply`] for springs on threads ([`Self::on_threads`]), each
    /// thread first setting its particles' forces to `m g`: one fork-join a
    /// step instead of two. `forces` need not be initialised.
    #[inline]
    pub(crate) fn apply_from(
        &mut self,
        g: DVec3,
        mass: &[f64],
        ctx: &ForceContext,
        forces: &mut [DVec3],
    ) {
        let springs = self.table.all();
        let threads = self.threads();
        if let Some(grid) = self.scratch.grid(springs, forces.len()) {
            let start = |r: std::ops::Range<usize>, f: &mut [DVec3]| {
                crate::forces::gravity::start_with_weights(g, &mass[r], f)
            };
            grid.add(springs, ctx.pos, ctx.vel, forces, threads, start);
            return;
        }
        self.scratch
            .parallel
            .apply(springs, ctx.pos, ctx.vel, forces, Some((g, mass)));
    }
}

impl Force for Springs {
    #[inline]
    fn apply(&mut self, ctx: &ForceContext, forces: &mut [DVec3]) {
        let (pos, vel) = (ctx.pos, ctx.vel);
        let springs = self.table.all();
        let threads = self.threads();
        if springs.len() < kernel::MIN_BLOCKED {
            kernel::plain(springs, pos, vel, forces);
        } else if let Some(grid) = self.scratch.grid(springs, forces.len()) {
            grid.add(springs, pos, vel, forces, threads, |_, _| {});
        } else if self.on_threads() {
            self.scratch.parallel.apply(springs, pos, vel, forces, None);
        } else {
            let block = self.scratch.block.get_or_insert_with(Box::default);
            kernel::run(springs, block, pos, vel, &mut kernel::Scatter::new(forces));
        }
    }

    /// With `d = x_b − x_a`, `n = d/l`: `∂f_a/∂x_a = −k (n nᵀ + (1 − r/l)
    /// (I − n nᵀ))` and `∂f_a/∂v_a = −c n nᵀ`. Under compression (`l < r`)
    /// the transverse term would make the system indefinite; it is dropped
    /// there (Choi & Ko 2002), as is the damping's dependence on position.
    fn jacobian(&self, ctx: &ForceContext, jac: &mut crate::Jacobian) -> bool {
        let t = &self.table;
        for (i, &[a, b]) in t.ends.iter().enumerate() {
            let (a, b) = (a as usize, b as usize);
            let d = ctx.pos[b] - ctx.pos[a];
            let l = d.length();
            if l == 0.0 {
                continue; // no direction: the force is zero there
            }
            let (k, c) = (t.stiffness[i], t.damping[i]);
            let across = k * (1.0 - t.rest_length[i] / l).max(0.0);
            jac.central(a, b, d / l, k, across, c);
        }
        true
    }

    fn potential_energy(&self, ctx: &ForceContext) -> f64 {
        self.iter()
            .map(|s| {
                let x = (ctx.pos[s.b as usize] - ctx.pos[s.a as usize]).length() - s.rest_length;
                0.5 * s.stiffness * x * x
            })
            .sum()
    }

    fn is_conservative(&self) -> bool {
        self.table.damping.iter().all(|&c| c == 0.0)
    }

    fn is_passive(&self) -> bool {
        true // damping only removes energy
    }

    fn name(&self) -> &str {
        "springs"
    }
}
