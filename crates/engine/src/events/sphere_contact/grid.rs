//! The broad phase of sphere contact: a uniform grid of cells twice the
//! largest radius, rebuilt at every check, so that each sphere is tested
//! only against the spheres of its 27 neighbouring cells (each cell
//! against itself and 13 neighbours). When the spheres fill their bounding
//! box the grid is a dense array filled by a counting sort; when they are
//! spread far apart, a hash map of the occupied cells. Then the swept test
//! for spheres that moved further than their radius.

use super::{pair_key, Pair, SphereContact};
use crate::event::EventContext;
use crate::particle::Properties;
use glam::DVec3;
use std::hash::Hasher;

/// A cheap, deterministic hasher for cell keys.
#[derive(Default)]
pub(super) struct CellHasher(u64);

impl Hasher for CellHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ b as u64).wrapping_mul(0x100_0000_01b3);
        }
    }
    fn write_u64(&mut self, k: u64) {
        // MurmurHash3's finaliser: every bit of the packed coordinates
        // reaches both the low bits (the bucket) and the high bits (the
        // table's tag), so neighbouring cells do not cluster.
        let mut k = k;
        k ^= k >> 33;
        k = k.wrapping_mul(0xff51_afd7_ed55_8ccd);
        k ^= k >> 33;
        k = k.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        self.0 = k ^ (k >> 33);
    }
}

/// `x.floor() as i64` for `|x| ≤ 10¹²`, without a call: on the baseline
/// x86-64 instruction set (no SSE4.1 rounding) `f64::floor` is a call into
/// libm, a tenth of the contact check's time in a large pile. Truncating
/// and stepping down below a negative non-integer gives the same integer
/// (every such `x` and its truncation are exact in f64).
#[inline(always)]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t - 1
    } else {
        t
    }
}

/// Each cell against itself and its 13 neighbours in the forward half of
/// the 3×3×3 block: every pair of neighbouring cells once.
const FORWARD: [[i64; 3]; 14] = [
    [0, 0, 0],
    [0, 0, 1],
    [0, 1, -1],
    [0, 1, 0],
    [0, 1, 1],
    [1, -1, -1],
    [1, -1, 0],
    [1, -1, 1],
    [1, 0, -1],
    [1, 0, 0],
    [1, 0, 1],
    [1, 1, -1],
    [1, 1, 0],
    [1, 1, 1],
];

/// The grid of one check: its cell size and the cells the spheres occupy.
#[derive(Clone, Copy)]
struct Grid {
    size: f64,
    /// The cells' coordinates are clamped to ±`limit`: a sphere further
    /// out shares the last cell with any others there (more pairs tested,
    /// none missed), and a neighbour's coordinate (±1) never overflows.
    limit: f64,
    lo: [i64; 3],
    hi: [i64; 3],
    /// A dense array of cells (else a hash map of the occupied ones).
    dense: bool,
    ny: i64,
    nz: i64,
    /// A sparse grid's key: each coordinate counted from one below `lo`,
    /// x in the highest bits, then y from bit `shift[1]`, z in the lowest,
    /// each in as many bits as it needs up to one above `hi`, so that the
    /// cells the spheres and their neighbours occupy have distinct keys,
    /// ordered as their coordinates (x, then y, then z).
    shift: [u32; 2],
}

/// Cells further out than 10¹² cell sizes are clamped (the first grid).
const FAR: f64 = 1e12;

/// The clamp when the cells from `lo` to `hi` cannot be keyed in 64 bits:
/// each coordinate in 21 bits.
const NEAR: f64 = ((1 << 20) - 2) as f64;

impl Grid {
    /// The cell of `x`.
    #[inline(always)]
    fn cell(&self, x: DVec3) -> [i64; 3] {
        let c = (x / self.size).clamp(DVec3::splat(-self.limit), DVec3::splat(self.limit));
        [floor_i64(c.x), floor_i64(c.y), floor_i64(c.z)]
    }

    /// The dense grid's index of cell `c`.
    #[inline(always)]
    fn linear(&self, c: [i64; 3]) -> u64 {
        (((c[0] - self.lo[0]) * self.ny + (c[1] - self.lo[1])) * self.nz + (c[2] - self.lo[2]))
            as u64
    }

    /// The key of cell `c`, within one cell of `lo` … `hi`.
    #[inline(always)]
    fn key(&self, c: [i64; 3]) -> u64 {
        if self.dense {
            self.linear(c)
        } else {
            let f = |k: usize| (c[k] - self.lo[k] + 1) as u64;
            (f(0) << self.shift[0]) | (f(1) << self.shift[1]) | f(2)
        }
    }

    /// The bits a sparse key's coordinate `k` takes.
    fn bits(&self, k: usize) -> u32 {
        64 - ((self.hi[k] - self.lo[k] + 2) as u64).leading_zeros()
    }
}

impl SphereContact {
    /// Fills `pairs` with the pairs at `pos` that overlap or are less than
    /// [`Self::margin`] apart; returns the deepest overlap.
    pub(super) fn find(&mut self, pos: &[DVec3], p: &Properties) -> f64 {
        self.pairs.clear();
        self.cells.clear();
        self.runs.clear();
        let n = pos.len();
        let mut largest = 0.0f64;
        self.def.targets.for_each(n, |i| {
            if p.radius[i] > 0.0 {
                largest = largest.max(p.radius[i]);
            }
        });
        if largest <= 0.0 {
            return 0.0;
        }
        match self.bin(pos, p, 2.0 * largest) {
            Some(grid) => self.test_neighbours(&grid, pos, p),
            None => 0.0,
        }
    }

    /// Sorts the spheres at `pos` into the cells of a grid of `size`
    /// (`cells`, by cell then by sphere; `starts` or `runs` say where
    /// each cell's run is); `None` when no sphere is where it can be.
    fn bin(&mut self, pos: &[DVec3], p: &Properties, size: f64) -> Option<Grid> {
        let n = pos.len();
        let mut grid = Grid {
            size,
            limit: FAR,
            lo: [0; 3],
            hi: [0; 3],
            dense: false,
            ny: 0,
            nz: 0,
            shift: [0; 2],
        };
        let total = loop {
            // Where the spheres are: the bounds of their cells.
            let mut count = 0usize;
            grid.lo = [i64::MAX; 3];
            grid.hi = [i64::MIN; 3];
            self.def.targets.for_each(n, |i| {
                if p.radius[i] > 0.0 && pos[i].is_finite() {
                    let c = grid.cell(pos[i]);
                    for (k, ck) in c.into_iter().enumerate() {
                        grid.lo[k] = grid.lo[k].min(ck);
                        grid.hi[k] = grid.hi[k].max(ck);
                    }
                    count += 1;
                }
            });
            if count == 0 {
                return None;
            }
            let dims = [0, 1, 2].map(|k| (grid.hi[k] - grid.lo[k] + 1) as f64);
            let total = dims[0] * dims[1] * dims[2];
            // A dense grid (an array of cell starts, filled by counting) when
            // the spheres fill their box; a hash map of occupied cells when
            // they are spread far apart.
            grid.dense = total <= (4 * count + 4096) as f64;
            [_, grid.ny, grid.nz] = dims.map(|d| d as i64);
            let bits = [0, 1, 2].map(|k| grid.bits(k));
            grid.shift = [bits[1] + bits[2], bits[2]];
            if grid.dense || bits.iter().sum::<u32>() <= 64 || grid.limit == NEAR {
                break total;
            }
            // Spread over more cells than 64 bits can key (with 6 cm
            // cells, about 150 km apart along every axis): the far ones
            // share cells.
            grid.limit = NEAR;
        };
        let cells = &mut self.cells;
        self.def.targets.for_each(n, |i| {
            if p.radius[i] > 0.0 && pos[i].is_finite() {
                cells.push((grid.key(grid.cell(pos[i])), i as u32));
            }
        });
        if grid.dense {
            self.counting_sort(total as usize);
        } else {
            self.index_runs();
        }
        Some(grid)
    }

    /// Sorts `cells` by cell and by sphere within a cell, over `total`
    /// cells of a dense grid, and fills `starts`.
    fn counting_sort(&mut self, total: usize) {
        let (cells, starts) = (&mut self.cells, &mut self.starts);
        starts.clear();
        starts.resize(total + 1, 0);
        for &(k, _) in cells.iter() {
            starts[k as usize + 1] += 1;
        }
        for k in 1..starts.len() {
            starts[k] += starts[k - 1];
        }
        let next = &mut self.next;
        next.clear();
        next.extend_from_slice(starts);
        self.sorted.clear();
        self.sorted.resize(cells.len(), (0, 0));
        for &(k, i) in cells.iter() {
            let at = &mut next[k as usize];
            self.sorted[*at as usize] = (k, i);
            *at += 1;
        }
        std::mem::swap(cells, &mut self.sorted);
    }

    /// Sorts `cells` and fills `runs` with each occupied cell's run.
    fn index_runs(&mut self) {
        let cells = &mut self.cells;
        cells.sort_unstable();
        let mut start = 0;
        while start < cells.len() {
            let key = cells[start].0;
            let mut end = start + 1;
            while end < cells.len() && cells[end].0 == key {
                end += 1;
            }
            self.runs.insert(key, (start as u32, end as u32));
            start = end;
        }
    }

    /// Tests each binned sphere against the spheres of its own cell and
    /// its forward neighbours, filling `pairs`; returns the deepest overlap.
    fn test_neighbours(&mut self, grid: &Grid, pos: &[DVec3], p: &Properties) -> f64 {
        let (starts, runs) = (&self.starts, &self.runs);
        // The spheres of cell `c`, as a range of `cells`.
        let run_of = |c: [i64; 3]| -> Option<(usize, usize)> {
            if grid.dense {
                if (0..3).any(|k| c[k] < grid.lo[k] || c[k] > grid.hi[k]) {
                    return None;
                }
                let k = grid.linear(c) as usize;
                let (s, e) = (starts[k] as usize, starts[k + 1] as usize);
                (e > s).then_some((s, e))
            } else {
                runs.get(&grid.key(c))
                    .map(|&(s, e)| (s as usize, e as usize))
            }
        };
        let mut deepest = 0.0f64;
        // The spheres' centres, radii and mobility copied in cell order, so
        // that the tests below read neighbours side by side.
        self.near.clear();
        self.near.extend(self.cells.iter().map(|&(_, i)| {
            let i = i as usize;
            (pos[i], p.radius[i], p.inv_mass[i] == 0.0)
        }));
        let margin = self.margin();
        self.overlapping = 0;
        let (cells, near, pairs, excluded, overlapping) = (
            &self.cells,
            &self.near,
            &mut self.pairs,
            &self.excluded,
            &mut self.overlapping,
        );
        let mut test = |x: usize, y: usize| {
            let ((pa, ra, fa), (pb, rb, fb)) = (near[x], near[y]);
            if fa && fb {
                return;
            }
            let reach = ra + rb;
            let d2 = (pb - pa).length_squared();
            let outer = reach + margin;
            if d2 >= outer * outer {
                return;
            }
            let (a, b) = (cells[x].1, cells[y].1);
            if !excluded.is_empty() && excluded.binary_search(&pair_key(a, b)).is_ok() {
                return;
            }
            deepest = deepest.max(reach - d2.sqrt());
            if d2 < reach * reach {
                *overlapping += 1;
            }
            let (a, b) = if a < b { (a, b) } else { (b, a) };
            pairs.push(Pair { a, b });
        };
        let mut start = 0;
        while start < cells.len() {
            let c = grid.cell(near[start].0);
            let end = run_of(c).map_or(start + 1, |r| r.1);
            for x in start..end {
                for y in x + 1..end {
                    test(x, y);
                }
            }
            for off in &FORWARD[1..] {
                let Some((s, e)) = run_of([c[0] + off[0], c[1] + off[1], c[2] + off[2]]) else {
                    continue;
                };
                for x in start..end {
                    for y in s..e {
                        test(x, y);
                    }
                }
            }
            start = end;
        }
        deepest
    }

    /// The swept test: how deep two spheres came into each other during
    /// the step, moving in straight lines from their start to their end,
    /// for every pair with a sphere that moved further than its radius
    /// (slower pairs cannot pass through each other unseen: crossing from
    /// touching on one side to the other takes 2 (r_a + r_b), and each
    /// moved at most its radius). Each fast sphere is tested against every
    /// sphere whose path's box comes near its own: cheap for a few fast
    /// spheres, quadratic if most move further than their radius in a step
    /// (where the remedy is a smaller step).
    pub(super) fn swept(&mut self, ctx: &EventContext) -> f64 {
        let (x0, x1, p) = (ctx.start_pos, ctx.pos, ctx.particles);
        let n = x0.len().min(x1.len());
        self.fast.clear();
        self.moving.clear();
        let (fast, moving) = (&mut self.fast, &mut self.moving);
        let usable = |i: usize| p.radius[i] > 0.0 && x0[i].is_finite() && x1[i].is_finite();
        self.def.targets.for_each(n, |i| {
            let r = p.radius[i];
            if usable(i) && (x1[i] - x0[i]).length_squared() > r * r {
                fast.push(i as u32);
            }
        });
        if fast.is_empty() {
            return 0.0;
        }
        // Every sphere's path, as a box grown by its radius.
        self.def.targets.for_each(n, |i| {
            if usable(i) {
                let r = p.radius[i];
                moving.push((i as u32, x0[i].min(x1[i]) - r, x0[i].max(x1[i]) + r));
            }
        });
        let mut deepest = 0.0f64;
        for &i in &self.fast {
            let i = i as usize;
            let r = p.radius[i];
            let (lo, hi) = (x0[i].min(x1[i]) - r, x0[i].max(x1[i]) + r);
            for &(j, jlo, jhi) in &self.moving {
                let j = j as usize;
                if j == i
                    || jlo.cmpgt(hi).any()
                    || jhi.cmplt(lo).any()
                    || (p.inv_mass[i] == 0.0 && p.inv_mass[j] == 0.0)
                {
                    continue;
                }
                let key = pair_key(i as u32, j as u32);
                if !self.excluded.is_empty() && self.excluded.binary_search(&key).is_ok() {
                    continue;
                }
                // Closest approach of the relative motion d(t) = d0 + t m.
                let d0 = x0[j] - x0[i];
                let m = (x1[j] - x1[i]) - d0;
                let mm = m.length_squared();
                let t = if mm > 0.0 {
                    (-d0.dot(m) / mm).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                deepest = deepest.max(r + p.radius[j] - (d0 + m * t).length());
            }
        }
        deepest
    }
}

#[cfg(test)]
mod tests {
    use super::floor_i64;

    /// The grid's cells must be the ones `f64::floor` gives, or the pairs
    /// would be found in another order (other bits).
    #[test]
    fn floor_without_a_call_agrees_with_f64_floor() {
        let mut xs = vec![0.0, -0.0, 0.5, -0.5, 1.0, -1.0, 1e12, -1e12, 1e12 - 0.5];
        xs.extend([f64::EPSILON, -f64::EPSILON, 1.0 - f64::EPSILON / 2.0]);
        xs.extend([
            -1.0 + f64::EPSILON / 2.0,
            -1e12 + 0.25,
            -(2f64.powi(39) + 0.5),
        ]);
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..100_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            // Uniform over ±2^k for k up to 40: many scales, both signs.
            let scale = (1u64 << (s % 41)) as f64;
            xs.push(((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * scale);
        }
        for x in xs {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x:e}");
        }
    }
}
